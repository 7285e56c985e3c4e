import { describe, expect, it } from 'vitest';
import { PointSet } from '../src/api';
import { boxHolds, boxParam, detailBox, lookedAtPoint, mergeDetail, nearBoxCentre } from '../src/detail';

// Points of a rows x cols grid, one per listed cell, at (col, 10, -row) (a wall 10 m ahead), flag = `flag`.
function grid(rows: number, cols: number, cells: number[], flag = 0): PointSet {
  const n = cells.length;
  return {
    count: n,
    rows,
    cols,
    xyz: new Float32Array(cells.flatMap((cell) => [cell % cols, 10, -Math.floor(cell / cols)])),
    cells: new Uint32Array(cells),
    rgb: new Uint8Array(3 * n).fill(7),
    flags: new Uint8Array(n).fill(flag),
  };
}

describe('detailBox', () => {
  it('centres a square of about the cells asked on the cell', () => {
    const box = detailBox(1000, 2000, 500, 700, 10_000);
    expect(box).toEqual({ col: 650, row: 450, width: 100, height: 100 });
    expect(boxHolds(box, 500, 700)).toBe(true);
    expect(boxParam(box)).toBe('650,450,100,100');
  });
  it('moves the box inside the grid at its borders and clips it to a smaller grid', () => {
    expect(detailBox(1000, 2000, 3, 1998, 10_000)).toEqual({ col: 1900, row: 0, width: 100, height: 100 });
    expect(detailBox(40, 2000, 20, 10, 10_000)).toEqual({ col: 0, row: 0, width: 100, height: 40 });
  });
  it('asks again only when the camera looks outside the middle half', () => {
    const box = { col: 100, row: 200, width: 100, height: 100 };
    expect(nearBoxCentre(box, 250, 150)).toBe(true);
    expect(nearBoxCentre(box, 225, 125)).toBe(true);
    expect(nearBoxCentre(box, 220, 150)).toBe(false);
    expect(nearBoxCentre(box, 250, 180)).toBe(false);
  });
});

describe('lookedAtPoint', () => {
  const wall = grid(
    20,
    30,
    Array.from({ length: 600 }, (_, i) => i),
  );
  it('finds the point on the view axis', () => {
    // From (12, 0, -5) straight ahead (+y): the cell at column 12, row 5.
    const index = lookedAtPoint(wall, [12, 0, -5], [0, 1, 0]);
    expect(wall.cells[index]).toBe(5 * 30 + 12);
  });
  it('takes the nearer of two points on the axis and none behind the eye', () => {
    const two = grid(20, 30, [5 * 30 + 12, 5 * 30 + 13]);
    two.xyz.set([12, 4, -5], 3); // the second point in front of the wall, on the same axis
    expect(lookedAtPoint(two, [12, 0, -5], [0, 1, 0])).toBe(1);
    expect(lookedAtPoint(two, [12, 20, -5], [0, 1, 0])).toBe(-1);
  });
});

describe('mergeDetail', () => {
  it('draws the coarse points outside the box and every detail point', () => {
    const rows = 8,
      cols = 8;
    const coarse = grid(
      rows,
      cols,
      Array.from({ length: 64 }, (_, i) => i).filter((i) => Math.floor(i / cols) % 2 === 0 && i % 2 === 0),
    );
    const box = { col: 2, row: 2, width: 3, height: 4 };
    const inBox: number[] = [];
    for (let r = 2; r < 6; ++r) for (let c = 2; c < 5; ++c) inBox.push(r * cols + c);
    const detail = grid(rows, cols, inBox, 2);
    const merged = mergeDetail(coarse, detail, box);
    const outside = [...coarse.cells].filter((cell) => !boxHolds(box, Math.floor(cell / cols), cell % cols));
    expect([...merged.cells]).toEqual([...outside, ...inBox]);
    expect(merged.count).toBe(outside.length + inBox.length);
    // Each cell once, the box's from the detail (its flags), the rest from the coarse level.
    expect(new Set(merged.cells).size).toBe(merged.count);
    expect([...merged.flags.subarray(outside.length)].every((f) => f === 2)).toBe(true);
    expect([...merged.flags.subarray(0, outside.length)].every((f) => f === 0)).toBe(true);
    const last = merged.count - 1;
    expect([...merged.xyz.subarray(3 * last, 3 * last + 3)]).toEqual([4, 10, -5]);
  });
});
