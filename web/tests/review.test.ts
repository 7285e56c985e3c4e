import { describe, expect, it } from 'vitest';
import {
  PendingReview,
  decisionBody,
  groupCandidates,
  patchInside,
  patchRect,
  verdictText,
} from '../src/review';

function candidate(index: number, cluster: number, accepted = false) {
  return {
    index,
    source: [10 + index, 20] as [number, number],
    difference: 100 * (index + 1),
    cluster,
    accepted,
    test: 'histogram',
    value: 0.31,
    threshold: 0.15,
    margin: -1.07,
  };
}

function pending(): PendingReview {
  return {
    state: 'review',
    channel: 'color',
    rows: 60,
    cols: 90,
    hole_cells: 300,
    decisions: [],
    review: {
      review_point: 0,
      iteration: 12,
      target: [44, 15],
      patch_radius: 4,
      candidates: [candidate(0, 0), candidate(1, 1), candidate(2, 0), candidate(3, 2), candidate(4, 1)],
      clusters: [
        { index: 0, representative: 0, members: [0, 2] },
        { index: 1, representative: 1, members: [1, 4] },
        { index: 2, representative: 3, members: [3] },
      ],
    },
  };
}

describe('groupCandidates', () => {
  it('gives one group per cluster with its best member first', () => {
    const groups = groupCandidates(pending());
    expect(groups.map((g) => g.cluster)).toEqual([0, 1, 2]);
    expect(groups.map((g) => g.representative.index)).toEqual([0, 1, 3]);
    expect(groups.map((g) => g.members.map((m) => m.index))).toEqual([[0, 2], [1, 4], [3]]);
    expect(groups[2].rank).toBe(4);
    expect(groups.reduce((n, g) => n + g.members.length, 0)).toBe(5);
  });
  it('refuses clusters that disagree with their candidates', () => {
    const broken = pending();
    broken.review.clusters[0].members.push(1); // candidate 1 is in cluster 1
    expect(() => groupCandidates(broken)).toThrow(/candidate 1 is not in cluster 0/);
    const missing = pending();
    missing.review.clusters[2].representative = 9;
    expect(() => groupCandidates(missing)).toThrow(/no representative/);
  });
});

describe('review helpers', () => {
  it('words the verdict', () => {
    expect(verdictText(candidate(0, 0))).toBe('rejected by histogram: 0.31 > 0.15');
    expect(verdictText(candidate(0, 0, true))).toBe('passes');
    // A test that measured nothing sends NaN, null in JSON: worded, not thrown on.
    expect(verdictText({ ...candidate(0, 0), value: null })).toBe('rejected by histogram: none > 0.15');
  });
  it('places patches in image pixels', () => {
    expect(patchRect([44, 15], 4)).toEqual({ x: 11, y: 40, size: 9 });
    expect(patchInside([4, 4], 4, 60, 90)).toBe(true);
    expect(patchInside([3, 40], 4, 60, 90)).toBe(false);
    expect(patchInside([55, 85], 4, 60, 90)).toBe(true);
    expect(patchInside([56, 85], 4, 60, 90)).toBe(false);
  });
  it('builds the decision body', () => {
    expect(decisionBody({ candidate: 3 })).toEqual({ candidate: 3 });
    expect(decisionBody({ source: [30, 60] })).toEqual({ source: [30, 60] });
  });
});
