// The three kinds of correspondences of the thesis's selection tool (3.2.1), each picked as two clicks:
//   photo-scan   a photo pixel, then a scan cell (ray image or 3-D view)  -> resection and recolouring
//   scan-scan    a cell of this scan, then a cell of another open scan     -> landmark registration
//   photo-photo  a pixel of the photo, then one of the second photo        -> homography / fundamental
// PairCollector holds the half-made pair and the list, and builds the request of each route (docs/api.md).

export type PairMode = 'photo-scan' | 'scan-scan' | 'photo-photo';
export type Point2 = [number, number];

export interface ModeInfo {
  first: string; // what the first click picks
  second: string;
  route: string; // under /api/docs/ID/
  action: string; // the button's words
  minimum: number; // pairs the library needs
}

export const MODES: Record<PairMode, ModeInfo> = {
  'photo-scan': {
    first: 'a photo pixel',
    second: 'the same spot in the scan (Pick tool)',
    route: 'recolor',
    action: 'Recolour',
    minimum: 6,
  },
  'scan-scan': {
    first: 'a cell of this scan (Pick tool)',
    second: 'the same spot in the other scan',
    route: 'align',
    action: 'Align',
    minimum: 3,
  },
  'photo-photo': {
    first: 'a pixel of the photo',
    second: 'the same spot in the second photo',
    route: 'photo-match',
    action: 'Match photos',
    minimum: 4,
  },
};

export type Pair = { first: Point2; second: Point2 };

export class PairCollector {
  pending: Point2 | null = null;
  readonly pairs: Pair[] = [];

  constructor(public mode: PairMode) {}

  // The first half of a pair (replaces a pending one).
  first(point: Point2) {
    this.pending = [point[0], point[1]];
  }

  // The second half: completes the pending pair and returns it, or null when there is no first half.
  second(point: Point2): Pair | null {
    if (!this.pending) return null;
    const pair = { first: this.pending, second: [point[0], point[1]] as Point2 };
    this.pairs.push(pair);
    this.pending = null;
    return pair;
  }

  undoLast() {
    if (this.pending) this.pending = null;
    else this.pairs.pop();
  }

  clear() {
    this.pending = null;
    this.pairs.length = 0;
  }

  ready(minimum = MODES[this.mode].minimum): boolean {
    return this.pairs.length >= minimum;
  }

  // The request body of the mode's route. photo-scan: pixels are [x, y] and cells [row, col];
  // scan-scan: `target` is the other scan's id; photo-photo: `model` homography or fundamental.
  body(extra: { target?: number; model?: 'homography' | 'fundamental' } = {}): Record<string, unknown> {
    switch (this.mode) {
      case 'photo-scan':
        return { pairs: this.pairs.map((p) => ({ pixel: p.first, cell: p.second })) };
      case 'scan-scan':
        if (extra.target === undefined) throw new Error('landmarks: choose the other scan first');
        return {
          target: extra.target,
          pairs: this.pairs.map((p) => ({ cell: p.first, target_cell: p.second })),
        };
      case 'photo-photo':
        return {
          model: extra.model ?? 'homography',
          pairs: this.pairs.map((p) => ({ pixel_a: p.first, pixel_b: p.second })),
        };
    }
  }
}
