// The correspondence panel: the mode (photo <-> scan, scan <-> scan, photo <-> photo), the pictures the clicks
// go to (the photo, the second photo, the other scan's ray image) and the button that sends the pairs to the
// mode's route (docs/api.md). The clicks in the editor's own ray image and 3-D view arrive through pickCell.
import { Api, DocumentInfo, JobInfo, Narrowed, precision } from './api';
import {
  AlignOptions,
  AlignReply,
  DocumentsReply,
  LandmarkAlignment,
  PhotoMatchReply,
  PhotoPairModel,
} from './api_types.generated';
import { MODES, PairCollector, PairMode, Point2 } from './pairs';
import { RayView } from './rayview';

export interface PairsContext {
  api: Api;
  doc: () => DocumentInfo | null;
  status: (text: string) => void;
  runJob: (path: string, body: unknown, what: string) => Promise<JobInfo | null>;
  refresh: () => Promise<void>;
}

const element = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

export class PairsPanel {
  readonly pairs = new PairCollector('photo-scan');
  private photoA: HTMLImageElement | null = null;
  private photoB: HTMLImageElement | null = null;
  residuals: number[] | null = null; // per pair of the last recolouring: reprojection error, px
  private inliers: number[] | null = null; // per pair of the last photo match: 1 = inlier
  readonly targetView: RayView;
  private targetDoc: DocumentInfo | null = null;
  shownTarget = 0; // the id of the scan the target view shows (0 = none yet)

  constructor(private context: PairsContext) {
    this.targetView = new RayView(element<HTMLCanvasElement>('target-ray'));
    this.targetView.brush = 'none';
    this.targetView.onPick = (cell) => {
      if (this.pairs.mode !== 'scan-scan') return;
      this.targetView.pick(cell);
      this.second([cell.row, cell.col]);
    };
    element<HTMLSelectElement>('pair-mode').addEventListener('change', (event) =>
      this.setMode((event.target as HTMLSelectElement).value as PairMode),
    );
    for (const [id, which] of [
      ['photo', 'a'],
      ['photo-b', 'b'],
    ] as const) {
      const canvas = element<HTMLCanvasElement>(id);
      canvas.addEventListener('click', (event) => this.clickPhoto(which, canvas, event));
    }
    element<HTMLInputElement>('photo-file').addEventListener('change', (event) => this.upload(event, 'a'));
    element<HTMLInputElement>('photo-b-file').addEventListener('change', (event) => this.upload(event, 'b'));
    element<HTMLSelectElement>('align-target').addEventListener('change', () => this.showTarget());
    element('recolor').addEventListener('click', () => this.solve());
    element('pairs-undo').addEventListener('click', () => {
      this.pairs.undoLast();
      this.update();
    });
    new ResizeObserver(() => this.draw()).observe(element('photo-panel'));
  }

  // A cell picked in the editor's ray image or 3-D view.
  pickCell(cell: { row: number; col: number }) {
    if (this.pairs.mode === 'photo-scan') this.second([cell.row, cell.col]);
    if (this.pairs.mode === 'scan-scan') {
      this.pairs.first([cell.row, cell.col]);
      this.context.status(
        `cell (${cell.row}, ${cell.col}) of this scan: now pick ${MODES['scan-scan'].second}`,
      );
      this.update();
    }
  }

  async setMode(mode: PairMode) {
    this.pairs.mode = mode;
    this.pairs.clear();
    this.inliers = null;
    element<HTMLSelectElement>('pair-mode').value = mode;
    element('photo-b-control').hidden = mode !== 'photo-photo';
    element('photo-model').hidden = mode !== 'photo-photo';
    element('align-target').hidden = mode !== 'scan-scan';
    element('photo').hidden = mode === 'scan-scan';
    element('photo-b').hidden = mode !== 'photo-photo';
    element('target-ray').hidden = mode !== 'scan-scan';
    element('recolor').textContent = MODES[mode].action;
    if (mode === 'scan-scan') await this.listTargets();
    element('photo-panel').hidden = mode === 'scan-scan' ? false : !this.photoA;
    this.update();
    this.context.status(
      `pairs: pick ${MODES[mode].first}, then ${MODES[mode].second}; ${MODES[mode].minimum} or more pairs`,
    );
  }

  // The other open scans, for landmarks.
  async listTargets() {
    const doc = this.context.doc();
    const { documents } =
      await this.context.api.json<Narrowed<DocumentsReply, { documents: DocumentInfo[] }>>('/api/docs');
    const others = documents.filter((d) => d.id !== doc?.id);
    const select = element<HTMLSelectElement>('align-target');
    const keep = select.value;
    select.replaceChildren(...others.map((d) => new Option(`${d.name} (#${d.id})`, String(d.id))));
    if (others.some((d) => String(d.id) === keep)) select.value = keep;
    if (others.length === 0) this.context.status('landmarks: open a second scan to register this one to');
    await this.showTarget();
  }

  private async showTarget() {
    const id = Number(element<HTMLSelectElement>('align-target').value);
    if (!id) return;
    const api = this.context.api;
    this.targetDoc = await api.json<DocumentInfo>(`/api/docs/${id}`);
    const d = this.targetDoc;
    const channel = d.channels.includes('color')
      ? 'rgb'
      : d.channels.includes('intensity')
        ? 'intensity'
        : 'range';
    const aspect = d.azimuth_step_deg > 0 ? d.elevation_step_deg / d.azimuth_step_deg : 1;
    await this.targetView.show(
      id,
      d.version,
      api.url(`/api/docs/${id}/image.png`, { channel, v: d.version }),
      null,
      null,
      null,
      d.rows,
      d.cols,
      aspect,
      false,
    );
    this.shownTarget = id;
  }

  private second(point: Point2) {
    const pair = this.pairs.second(point);
    if (!pair) {
      this.context.status(`pick ${MODES[this.pairs.mode].first} first`);
      return;
    }
    this.inliers = null;
    this.update();
    this.context.status(
      `${this.pairs.pairs.length} pairs; pick ${MODES[this.pairs.mode].first} for the next`,
    );
  }

  private clickPhoto(which: 'a' | 'b', canvas: HTMLCanvasElement, event: MouseEvent) {
    const photo = which === 'a' ? this.photoA : this.photoB;
    if (!photo) return;
    const scale = Number(canvas.dataset.scale);
    const pixel: Point2 = [event.offsetX / scale, event.offsetY / scale];
    if (pixel[0] >= photo.width || pixel[1] >= photo.height) return;
    if (which === 'b') return this.second(pixel);
    if (this.pairs.mode === 'scan-scan') return;
    this.pairs.first(pixel);
    this.update();
    this.context.status(
      `photo pixel (${pixel[0].toFixed(1)}, ${pixel[1].toFixed(1)}): now pick ${MODES[this.pairs.mode].second}`,
    );
  }

  private async upload(event: Event, slot: 'a' | 'b') {
    const file = (event.target as HTMLInputElement).files?.[0];
    const doc = this.context.doc();
    if (!file || !doc) return;
    const api = this.context.api;
    await this.usePhoto(slot, () =>
      fetch(api.url(`/api/docs/${doc.id}/photo`, { slot }), {
        method: 'POST',
        body: file,
        headers: { 'Content-Type': file.type },
      }),
    );
  }

  // Photo K of the scan's own E57 file (images2D) as the photo to recolour from.
  async useE57Photo(index: number, slot: 'a' | 'b' = 'a') {
    const doc = this.context.doc();
    if (!doc) return;
    const api = this.context.api;
    await this.usePhoto(slot, () =>
      fetch(api.url(`/api/docs/${doc.id}/photo-from-e57`), {
        method: 'POST',
        headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify({ image: index, slot }),
      }),
    );
  }

  private async usePhoto(slot: 'a' | 'b', send: () => Promise<Response>) {
    const doc = this.context.doc();
    if (!doc) return;
    const api = this.context.api;
    try {
      const response = await send();
      if (!response.ok) throw new Error((await response.json()).error);
      const image = new Image();
      image.onload = () => this.draw();
      image.src = api.url(`/api/docs/${doc.id}/photo.png`, { slot, v: Date.now() });
      if (slot === 'a') this.photoA = image;
      else this.photoB = image;
      element('photo-panel').hidden = false;
      this.pairs.clear();
      this.update();
      this.context.status(
        `photo loaded: pick ${MODES[this.pairs.mode].first}, then ${MODES[this.pairs.mode].second}`,
      );
    } catch (error) {
      this.context.status(`photo: ${(error as Error).message}`);
    }
  }

  private async solve() {
    const doc = this.context.doc();
    if (!doc) return this.context.status('open a scan first');
    const mode = this.pairs.mode;
    const api = this.context.api;
    try {
      if (mode === 'photo-scan') {
        const finished = await this.context.runJob(
          `/api/docs/${doc.id}/recolor`,
          this.pairs.body(),
          'recolour',
        );
        // Each pair's residual after the resection: a pair far off is a wrong click (refuse it, pick again).
        const result = finished?.result as
          { reprojection_error_px?: number[]; inlier?: number[]; rms_px?: number } | undefined;
        if (finished?.state === 'done' && result?.reprojection_error_px) {
          this.residuals = result.reprojection_error_px;
          const list = result.reprojection_error_px
            .map((e, i) => `${i + 1}: ${e.toFixed(1)}${result.inlier?.[i] === 0 ? ' (outlier)' : ''}`)
            .join(', ');
          element('pairs').textContent = `${this.pairs.pairs.length} pairs`;
          element('pairs').title = `pair residuals (px): ${list}`;
          this.context.status(
            `recolour: pair residuals (px) ${list}; RMS ${result.rms_px?.toFixed(2)} px. ${element('status').textContent}`,
          );
        }
      } else if (mode === 'scan-scan') {
        const target = Number(element<HTMLSelectElement>('align-target').value);
        const result = await api.json<LandmarkAlignment & AlignReply>(
          `/api/docs/${doc.id}/align`,
          {},
          this.pairs.body({ target }),
        );
        await this.context.refresh();
        this.context.status(
          `aligned to scan #${target}: ${this.pairs.pairs.length} landmarks, RMS ${(1000 * (result.rms_m ?? NaN)).toFixed(1)} mm (undo restores the pose)`,
        );
      } else {
        const model = element<HTMLSelectElement>('photo-model').value as AlignOptions['model'];
        const result = await api.json<PhotoPairModel & PhotoMatchReply>(
          `/api/docs/${doc.id}/photo-match`,
          {},
          this.pairs.body({ model }),
        );
        this.inliers = result.inlier;
        this.draw();
        const outliers = result.inlier.filter((v) => !v).length;
        this.context.status(
          `${model}: RMS ${(result.rms_px ?? NaN).toFixed(2)} px over the inliers, ${outliers} outlier pairs (red); matrix ${result.matrix_row_major.map((v) => precision(v, 4)).join(' ')}`,
        );
      }
    } catch (error) {
      this.context.status(`${MODES[mode].action}: ${(error as Error).message}`);
    }
  }

  private update() {
    element('pairs').textContent = `${this.pairs.pairs.length} pairs`;
    this.draw();
  }

  private draw() {
    const mode = this.pairs.mode;
    const firsts = mode === 'scan-scan' ? [] : this.pairs.pairs.map((p) => p.first);
    const seconds = mode === 'photo-photo' ? this.pairs.pairs.map((p) => p.second) : [];
    drawPhoto(
      element<HTMLCanvasElement>('photo'),
      this.photoA,
      firsts,
      mode === 'scan-scan' ? null : this.pairs.pending,
      this.inliers,
    );
    if (mode === 'photo-photo')
      drawPhoto(element<HTMLCanvasElement>('photo-b'), this.photoB, seconds, null, this.inliers);
  }
}

// The photo scaled into its canvas, the pairs' pixels as yellow squares (red: an outlier of the last fit) and
// the pending pixel outlined.
function drawPhoto(
  canvas: HTMLCanvasElement,
  photo: HTMLImageElement | null,
  points: Point2[],
  pending: Point2 | null,
  inliers: number[] | null,
) {
  const context = canvas.getContext('2d');
  if (!context || !photo || !photo.complete || canvas.hidden) return;
  canvas.width = Math.max(1, canvas.clientWidth);
  canvas.height = Math.max(1, canvas.clientHeight);
  const scale = Math.min(canvas.width / photo.width, canvas.height / photo.height);
  context.drawImage(photo, 0, 0, photo.width * scale, photo.height * scale);
  points.forEach((point, i) => {
    context.fillStyle = inliers && !inliers[i] ? '#f33' : '#ff0';
    context.fillRect(point[0] * scale - 3, point[1] * scale - 3, 6, 6);
  });
  if (pending) {
    context.strokeStyle = '#0ff';
    context.strokeRect(pending[0] * scale - 5, pending[1] * scale - 5, 10, 10);
  }
  canvas.dataset.scale = String(scale);
}
