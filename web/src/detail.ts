// Refining the 3-D view where the camera looks (issue 34): a large scan's points are held at a coarse level
// everywhere and at full resolution in a box of cells around the point the camera looks at, both within the
// browser's point budget. The server gives a box's points whole and as deltas (`points?box=`, docs/api.md).
import { PointSet, selectPoints } from './api';

// Columns [col, col + width) and rows [row, row + height) of the scan's grid (the server's `box` parameter).
export interface CellBox {
  col: number;
  row: number;
  width: number;
  height: number;
}

export const boxParam = (box: CellBox) => `${box.col},${box.row},${box.width},${box.height}`;

// The square box of about `cells` cells centred on (row, col), moved to lie inside the rows x cols grid and
// clipped to it when the grid is smaller.
export function detailBox(rows: number, cols: number, row: number, col: number, cells: number): CellBox {
  const side = Math.max(1, Math.floor(Math.sqrt(cells)));
  const height = Math.min(side, rows),
    width = Math.min(side, cols);
  const top = Math.min(Math.max(0, row - Math.floor(height / 2)), rows - height);
  const left = Math.min(Math.max(0, col - Math.floor(width / 2)), cols - width);
  return { col: left, row: top, width, height };
}

export function boxHolds(box: CellBox, row: number, col: number): boolean {
  return row >= box.row && row < box.row + box.height && col >= box.col && col < box.col + box.width;
}

// Whether (row, col) lies in the middle half of the box (its central box of half the side): the camera still
// looks well inside the detail held, so it is not fetched again.
export function nearBoxCentre(box: CellBox, row: number, col: number): boolean {
  const inner: CellBox = {
    col: box.col + Math.floor(box.width / 4),
    row: box.row + Math.floor(box.height / 4),
    width: Math.ceil(box.width / 2),
    height: Math.ceil(box.height / 2),
  };
  return boxHolds(inner, row, col);
}

// The point the camera looks at: of the points in front of the eye, those within 1e-3 rad of the smallest angle
// from the view direction (a unit vector), the nearest. -1 when none is in front.
export function lookedAtPoint(
  points: PointSet,
  eye: [number, number, number],
  direction: [number, number, number],
): number {
  const sines = new Float32Array(points.count).fill(Infinity);
  const depths = new Float32Array(points.count);
  let smallest = Infinity;
  for (let i = 0; i < points.count; ++i) {
    const dx = points.xyz[3 * i] - eye[0],
      dy = points.xyz[3 * i + 1] - eye[1],
      dz = points.xyz[3 * i + 2] - eye[2];
    const depth = dx * direction[0] + dy * direction[1] + dz * direction[2];
    if (!(depth > 1e-3)) continue;
    // The sine of the angle from the view axis: |d x direction| / |d|.
    const cx = dy * direction[2] - dz * direction[1],
      cy = dz * direction[0] - dx * direction[2],
      cz = dx * direction[1] - dy * direction[0];
    sines[i] = Math.hypot(cx, cy, cz) / Math.hypot(dx, dy, dz);
    depths[i] = depth;
    smallest = Math.min(smallest, sines[i]);
  }
  let best = -1;
  if (smallest === Infinity) return best;
  for (let i = 0; i < points.count; ++i) {
    if (sines[i] <= smallest + 1e-3 && (best < 0 || depths[i] < depths[best])) best = i;
  }
  return best;
}

// What the view draws: the coarse points outside the box and every point of the detail (which holds the box's
// cells at full resolution, the coarse level's among them).
export function mergeDetail(coarse: PointSet, detail: PointSet, box: CellBox): PointSet {
  const keep: number[] = [];
  for (let i = 0; i < coarse.count; ++i) {
    const cell = coarse.cells[i];
    if (!boxHolds(box, Math.floor(cell / coarse.cols), cell % coarse.cols)) keep.push(i);
  }
  const outside = selectPoints(coarse, keep);
  const n = outside.count + detail.count;
  const grow = <T extends Float32Array | Uint32Array | Uint8Array>(
    a: T,
    b: T,
    make: (n: number) => T,
    k: number,
  ) => {
    const out = make(k * n);
    out.set(a.subarray(0, k * outside.count));
    out.set(b.subarray(0, k * detail.count), k * outside.count);
    return out;
  };
  return {
    count: n,
    rows: coarse.rows,
    cols: coarse.cols,
    xyz: grow(outside.xyz, detail.xyz, (m) => new Float32Array(m), 3),
    cells: grow(outside.cells, detail.cells, (m) => new Uint32Array(m), 1),
    rgb: grow(outside.rgb, detail.rgb, (m) => new Uint8Array(m), 3),
    flags: grow(outside.flags, detail.flags, (m) => new Uint8Array(m), 1),
  };
}
