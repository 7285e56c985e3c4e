import { describe, expect, it } from 'vitest';
import { PointSet } from '../src/api';
import { FLAG_BEHIND, VersionGate, applyDelta, parseDelta, parsePointsAnswer } from '../src/delta';

interface Row {
  key: number;
  xyz: number[];
  rgb: number[];
  flag: number;
  present?: boolean;
}

function points(rows: Row[]): PointSet {
  const n = rows.length;
  return {
    count: n,
    rows: 4,
    cols: 5,
    xyz: new Float32Array(rows.flatMap((r) => r.xyz)),
    cells: new Uint32Array(rows.map((r) => r.key & 0x7fffffff)),
    rgb: new Uint8Array(rows.flatMap((r) => r.rgb)),
    flags: new Uint8Array(rows.map((r) => r.flag)),
  };
}

function encodeDelta(rows: Row[], from = 3, to = 5) {
  const n = rows.length;
  const buffer = new ArrayBuffer(24 + 21 * n);
  const header = new DataView(buffer);
  [0x3144534c, n, 4, 5, from, to].forEach((value, i) => header.setUint32(4 * i, value, true));
  new Uint32Array(buffer, 24, n).set(rows.map((r) => r.key));
  new Float32Array(buffer, 24 + 4 * n, 3 * n).set(rows.flatMap((r) => r.xyz));
  new Uint8Array(buffer, 24 + 16 * n, 3 * n).set(rows.flatMap((r) => r.rgb));
  new Uint8Array(buffer, 24 + 19 * n, n).set(rows.map((r) => r.flag));
  new Uint8Array(buffer, 24 + 20 * n, n).set(rows.map((r) => (r.present === false ? 0 : 1)));
  return buffer;
}

const row = (key: number, v: number, flag = 0, present = true): Row => ({
  key,
  xyz: [v, v + 1, v + 2],
  rgb: [v, v, v],
  flag,
  present,
});
const behind = 0x80000000;

describe('deltas', () => {
  it('parses the header and arrays', () => {
    const delta = parseDelta(encodeDelta([row(2, 7), row(behind + 3, 9, FLAG_BEHIND, false)]));
    expect([delta.from, delta.to, delta.count, delta.rows, delta.cols]).toEqual([3, 5, 2, 4, 5]);
    expect(Array.from(delta.keys)).toEqual([2, behind + 3]);
    expect(Array.from(delta.present)).toEqual([1, 0]);
    expect(() => parseDelta(encodeDelta([row(1, 1)]).slice(0, 30))).toThrow(/expected/);
    expect('delta' in parsePointsAnswer(encodeDelta([]))).toBe(true);
  });
  it('adds, replaces and removes cells in key order, both layers', () => {
    const before = points([
      row(1, 10),
      row(4, 40),
      row(9, 90),
      row(behind + 1, 11, FLAG_BEHIND),
      row(behind + 4, 44, FLAG_BEHIND),
    ]);
    const delta = parseDelta(
      encodeDelta([
        row(0, 1), // added before every point
        row(4, 0, 0, false), // removed
        row(9, 99, 2), // replaced (now in the object)
        row(12, 120), // added between the layers
        row(behind + 2, 22, FLAG_BEHIND), // added behind
        row(behind + 4, 0, FLAG_BEHIND, false), // removed behind
      ]),
    );
    const after = applyDelta(before, delta);
    expect(Array.from(after.cells)).toEqual([0, 1, 9, 12, 1, 2]);
    expect(Array.from(after.flags)).toEqual([0, 0, 2, 0, FLAG_BEHIND, FLAG_BEHIND]);
    expect(Array.from(after.xyz.subarray(6, 9))).toEqual([99, 100, 101]);
    expect(Array.from(after.rgb.subarray(15, 18))).toEqual([22, 22, 22]);
    expect(after.count).toBe(6);
  });
  it('an empty delta keeps every point', () => {
    const before = points([row(1, 10), row(4, 40)]);
    const after = applyDelta(before, parseDelta(encodeDelta([])));
    expect(Array.from(after.cells)).toEqual([1, 4]);
    expect(Array.from(after.xyz)).toEqual(Array.from(before.xyz));
  });
});

describe('VersionGate', () => {
  it('drops an answer older than the one shown, per document', () => {
    const gate = new VersionGate();
    expect(gate.accept(1, 5)).toBe(true);
    expect(gate.accept(1, 4)).toBe(false); // a slow refresh that finished late
    expect(gate.accept(1, 5)).toBe(true); // the same version again is fine
    expect(gate.accept(2, 0)).toBe(true); // another document has its own order
    gate.forget(1);
    expect(gate.accept(1, 0)).toBe(true);
    expect(gate.version(1)).toBe(0);
  });
});

import { centrePoint, layerOf, visiblePoints } from '../src/pointview';

describe('layers and the first view', () => {
  const set = points([row(0, 1), row(7, 2, 1), row(12, 3, 2), row(behind + 12, 4, FLAG_BEHIND)]);
  it('sorts points into layers and hides one', () => {
    expect(Array.from(set.flags, layerOf)).toEqual(['original', 'synthesized', 'object', 'synthesized']);
    const shown = visiblePoints(set, new Set(['synthesized']));
    expect(Array.from(shown.cells)).toEqual([0, 12]);
    expect(Array.from(shown.xyz)).toEqual([1, 2, 3, 3, 4, 5]);
    expect(visiblePoints(set, new Set())).toBe(set);
  });
  it('finds the point where the ray image centre looks (front layer only)', () => {
    // 4 x 5 cells: the centre cell is row 2, col 2 = 12.
    expect(centrePoint(set)).toEqual([3, 4, 5]);
    expect(centrePoint(points([]))).toBeNull();
  });
});
