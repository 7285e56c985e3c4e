// Points that change by deltas (docs/api.md "Points"): GET /api/docs/ID/points?since=V answers only the cells
// that changed since version V (LSD1), which the client merges into the points it holds; whole scans travel
// once. And the order of answers: an answer about an older version never replaces a newer one.
import { PointSet, parsePoints } from './api';

const DELTA_MAGIC = 0x3144534c; // "LSD1"
export const FLAG_BEHIND = 4; // the point is on the layer behind a kept object (fill shadow)
const BEHIND_KEY = 0x80000000;

// The cells that changed between two versions: for each, its key (cell, + 2^31 on the layer behind), whether
// it has a point now, and the point (xyz, rgb, flags) when it has.
export interface PointDelta {
  from: number;
  to: number;
  rows: number;
  cols: number;
  count: number;
  keys: Uint32Array;
  xyz: Float32Array;
  rgb: Uint8Array;
  flags: Uint8Array;
  present: Uint8Array;
}

// Decodes an LSD1 answer: 24-byte header (magic, count, rows, cols, from version, to version; uint32
// little-endian), then keys uint32[n], xyz float32[3n], rgb uint8[3n], flags uint8[n], present uint8[n].
export function parseDelta(buffer: ArrayBuffer): PointDelta {
  if (buffer.byteLength < 24) throw new Error(`delta: ${buffer.byteLength} bytes is shorter than the header`);
  const header = new DataView(buffer, 0, 24);
  if (header.getUint32(0, true) !== DELTA_MAGIC) throw new Error('delta: not LSD1 data');
  const count = header.getUint32(4, true);
  if (buffer.byteLength !== 24 + 21 * count)
    throw new Error(`delta: ${buffer.byteLength} bytes, expected ${24 + 21 * count} for ${count} cells`);
  let offset = 24;
  const keys = new Uint32Array(buffer, offset, count);
  offset += 4 * count;
  const xyz = new Float32Array(buffer, offset, 3 * count);
  offset += 12 * count;
  const rgb = new Uint8Array(buffer, offset, 3 * count);
  offset += 3 * count;
  const flags = new Uint8Array(buffer, offset, count);
  offset += count;
  const present = new Uint8Array(buffer, offset, count);
  return {
    from: header.getUint32(16, true),
    to: header.getUint32(20, true),
    rows: header.getUint32(8, true),
    cols: header.getUint32(12, true),
    count,
    keys,
    xyz,
    rgb,
    flags,
    present,
  };
}

// Whole points (LSP1) or a delta (LSD1), told apart by the magic.
export function parsePointsAnswer(buffer: ArrayBuffer): { whole: PointSet } | { delta: PointDelta } {
  if (buffer.byteLength >= 4 && new DataView(buffer).getUint32(0, true) === DELTA_MAGIC)
    return { delta: parseDelta(buffer) };
  return { whole: parsePoints(buffer) };
}

const keyOf = (points: PointSet, i: number) =>
  points.cells[i] + (points.flags[i] & FLAG_BEHIND ? BEHIND_KEY : 0);

// The points after `delta`: both are in key order (the server writes the front layer row by row, then the layer
// behind), so one merge pass gives the new arrays; cells the delta does not name are copied as they were.
export function applyDelta(points: PointSet, delta: PointDelta): PointSet {
  let added = 0;
  for (let j = 0; j < delta.count; ++j) added += delta.present[j];
  const capacity = points.count + added;
  const xyz = new Float32Array(3 * capacity),
    cells = new Uint32Array(capacity);
  const rgb = new Uint8Array(3 * capacity),
    flags = new Uint8Array(capacity);
  let n = 0,
    i = 0;
  const copyOld = (from: number, to: number) => {
    // old points [from, to) in one block each
    const m = to - from;
    if (m <= 0) return;
    xyz.set(points.xyz.subarray(3 * from, 3 * to), 3 * n);
    cells.set(points.cells.subarray(from, to), n);
    rgb.set(points.rgb.subarray(3 * from, 3 * to), 3 * n);
    flags.set(points.flags.subarray(from, to), n);
    n += m;
  };
  for (let j = 0; j < delta.count; ++j) {
    const key = delta.keys[j];
    // Old points before this key stay: find the first old key >= key (binary search: a delta is usually small).
    let lo = i,
      hi = points.count;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (keyOf(points, mid) < key) lo = mid + 1;
      else hi = mid;
    }
    copyOld(i, lo);
    i = lo;
    if (i < points.count && keyOf(points, i) === key) ++i; // replaced or removed
    if (delta.present[j]) {
      xyz.set(delta.xyz.subarray(3 * j, 3 * j + 3), 3 * n);
      cells[n] = key & 0x7fffffff;
      rgb.set(delta.rgb.subarray(3 * j, 3 * j + 3), 3 * n);
      flags[n] = delta.flags[j];
      ++n;
    }
  }
  copyOld(i, points.count);
  return {
    count: n,
    rows: points.rows,
    cols: points.cols,
    xyz: xyz.subarray(0, 3 * n),
    cells: cells.subarray(0, n),
    rgb: rgb.subarray(0, 3 * n),
    flags: flags.subarray(0, n),
  };
}

// Applies answers in version order: each answer says the version it shows; one older than what is shown
// (a slow answer overtaken by a newer one) is dropped.
export class VersionGate {
  private shown = new Map<number, number>(); // document id -> the version shown

  // True when an answer of `version` about document `id` may be shown (it is not older than the shown one);
  // records it as shown.
  accept(id: number, version: number): boolean {
    const shown = this.shown.get(id) ?? -1;
    if (version < shown) return false;
    this.shown.set(id, version);
    return true;
  }

  version(id: number): number {
    return this.shown.get(id) ?? -1;
  }

  forget(id: number) {
    this.shown.delete(id);
  }
}
