import { describe, expect, it } from 'vitest';
import { MODES, PairCollector } from '../src/pairs';

describe('PairCollector', () => {
  it('makes a pair of two clicks, first then second', () => {
    const pairs = new PairCollector('photo-scan');
    expect(pairs.second([5, 6])).toBeNull(); // no first half yet
    pairs.first([10.5, 20.25]);
    pairs.first([11.5, 21.25]); // a new first click replaces the pending one
    expect(pairs.second([3, 4])).toEqual({ first: [11.5, 21.25], second: [3, 4] });
    expect(pairs.pending).toBeNull();
    expect(pairs.pairs.length).toBe(1);
  });
  it('builds each route body in the API form', () => {
    const scan = new PairCollector('photo-scan');
    scan.first([1.5, 2.5]);
    scan.second([7, 8]);
    expect(scan.body()).toEqual({ pairs: [{ pixel: [1.5, 2.5], cell: [7, 8] }] });
    const landmarks = new PairCollector('scan-scan');
    landmarks.first([3, 4]);
    landmarks.second([5, 6]);
    expect(landmarks.body({ target: 2 })).toEqual({
      target: 2,
      pairs: [{ cell: [3, 4], target_cell: [5, 6] }],
    });
    expect(() => landmarks.body()).toThrow(/other scan/);
    const photos = new PairCollector('photo-photo');
    photos.first([1, 2]);
    photos.second([3, 4]);
    expect(photos.body({ model: 'fundamental' })).toEqual({
      model: 'fundamental',
      pairs: [{ pixel_a: [1, 2], pixel_b: [3, 4] }],
    });
    expect(photos.body().model).toBe('homography');
  });
  it('knows when there are enough pairs and undoes the last click', () => {
    const pairs = new PairCollector('scan-scan');
    for (let i = 0; i < 3; ++i) {
      pairs.first([i, i]);
      pairs.second([i, i + 1]);
    }
    expect(MODES['scan-scan'].minimum).toBe(3);
    expect(pairs.ready()).toBe(true);
    pairs.first([9, 9]);
    pairs.undoLast(); // drops the pending half first
    expect(pairs.pairs.length).toBe(3);
    pairs.undoLast();
    expect(pairs.ready()).toBe(false);
    pairs.clear();
    expect(pairs.pairs.length).toBe(0);
  });
});
