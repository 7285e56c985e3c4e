import { describe, expect, it } from 'vitest';
import { parseBox, patchPixels } from '../src/picture';

// A width x height RGBA picture whose pixel (r, c) is [r, c, fill, 255].
function picture(width: number, height: number, fill: number) {
  const data = new Uint8ClampedArray(4 * width * height);
  for (let r = 0; r < height; ++r)
    for (let c = 0; c < width; ++c) data.set([r, c, fill, 255], 4 * (r * width + c));
  return data;
}

describe('parseBox', () => {
  it('reads col,row,width,height', () => {
    expect(parseBox('3,4,5,6')).toEqual({ col: 3, row: 4, width: 5, height: 6 });
    expect(parseBox('0,0,0,0')).toEqual({ col: 0, row: 0, width: 0, height: 0 });
  });
  it('refuses what is not four whole numbers >= 0', () => {
    for (const bad of [null, '', '1,2,3', '1,2,3,4,5', '1,-2,3,4', '1,2,x,4', '1.5,2,3,4'])
      expect(parseBox(bad)).toBeNull();
  });
});

describe('patchPixels', () => {
  it('replaces exactly the box and keeps every other pixel', () => {
    const width = 7,
      height = 5;
    const target = picture(width, height, 10);
    const before = target.slice();
    const box = { col: 2, row: 1, width: 3, height: 2 };
    const patch = new Uint8ClampedArray(4 * box.width * box.height).map((_, i) => 200 + (i % 50));
    patchPixels(target, width, height, patch, box);
    for (let r = 0; r < height; ++r) {
      for (let c = 0; c < width; ++c) {
        const at = Array.from(target.subarray(4 * (r * width + c), 4 * (r * width + c) + 4));
        const inside = r >= box.row && r < box.row + box.height && c >= box.col && c < box.col + box.width;
        const j = 4 * ((r - box.row) * box.width + (c - box.col));
        const expected = inside
          ? Array.from(patch.subarray(j, j + 4))
          : Array.from(before.subarray(4 * (r * width + c), 4 * (r * width + c) + 4));
        expect(at).toEqual(expected);
      }
    }
  });
  it('patches from the version held give the picture of the new version (remove, then undo)', () => {
    const width = 6,
      height = 4;
    const original = picture(width, height, 1);
    const removed = original.slice();
    const box = { col: 1, row: 1, width: 2, height: 2 };
    for (let r = 1; r < 3; ++r) for (let c = 1; c < 3; ++c) removed.set([9, 9, 9, 255], 4 * (r * width + c));
    const held = original.slice();
    const crop = (from: Uint8ClampedArray) => {
      const out = new Uint8ClampedArray(4 * box.width * box.height);
      for (let r = 0; r < box.height; ++r)
        out.set(
          from.subarray(
            4 * ((box.row + r) * width + box.col),
            4 * ((box.row + r) * width + box.col + box.width),
          ),
          4 * r * box.width,
        );
      return out;
    };
    patchPixels(held, width, height, crop(removed), box);
    expect(held).toEqual(removed);
    patchPixels(held, width, height, crop(original), box);
    expect(held).toEqual(original);
  });
  it('refuses a box outside the picture or a patch of the wrong size', () => {
    const target = picture(4, 4, 0);
    expect(() =>
      patchPixels(target, 4, 4, new Uint8ClampedArray(4 * 4), { col: 3, row: 0, width: 2, height: 2 }),
    ).toThrow(/outside/);
    expect(() =>
      patchPixels(target, 4, 4, new Uint8ClampedArray(4 * 3), { col: 0, row: 0, width: 2, height: 2 }),
    ).toThrow(/bytes/);
  });
});
