// The patch review of the inpainting (docs/api.md "Patch review"): what GET /api/docs/ID/inpaint/review answers,
// grouped for display. The server lists the candidates best first with their cluster; the panel shows one tile
// per cluster (its representative, the best member) and accepts a candidate by index.

import type {
  PendingReviewReply,
  ReviewCandidateEntry,
  ReviewClusterEntry,
  ReviewDetail,
} from './api_types.generated';
import { type Narrowed, precision } from './api';

// The server's types (api_types.generated.ts, narrowed as api.ts says): the cells as [row, col] tuples, the fixed
// strings as unions. A candidate's numbers stay `number | null`: a NaN (a test that measured nothing) is null.
export type ReviewCandidate = Narrowed<ReviewCandidateEntry, { source: [number, number] }>;

export type ReviewCluster = ReviewClusterEntry;

export type PendingReview = Narrowed<
  PendingReviewReply,
  {
    state: 'review';
    channel: 'color' | 'intensity';
    decisions: { target: [number, number]; source: [number, number] }[];
    review: Narrowed<ReviewDetail, { target: [number, number]; candidates: ReviewCandidate[] }>;
  }
>;

export interface ClusterGroup {
  cluster: number;
  representative: ReviewCandidate;
  members: ReviewCandidate[];
  rank: number; // 1-based rank of the representative among all candidates
}

// One group per cluster in the server's order (by their best member), members best first. Throws on a review
// whose clusters and candidates disagree, so a broken answer shows as an error rather than as wrong tiles.
export function groupCandidates(pending: PendingReview): ClusterGroup[] {
  const { candidates, clusters } = pending.review;
  return clusters.map((cluster) => {
    const members = cluster.members.map((index) => {
      const candidate = candidates[index];
      if (!candidate || candidate.cluster !== cluster.index)
        throw new Error(`review: candidate ${index} is not in cluster ${cluster.index}`);
      return candidate;
    });
    const representative = candidates[cluster.representative];
    if (!representative || representative.cluster !== cluster.index)
      throw new Error(`review: cluster ${cluster.index} has no representative`);
    return { cluster: cluster.index, representative, members, rank: representative.index + 1 };
  });
}

// "passes" or "rejected by histogram: 0.31 > 0.15".
export function verdictText(candidate: ReviewCandidate): string {
  if (candidate.accepted) return 'passes';
  return `rejected by ${candidate.test}: ${precision(candidate.value, 2)} > ${precision(candidate.threshold, 2)}`;
}

// The patch centred at [row, col] as a rectangle of the ray image, pixels: (2R + 1)² from (col − R, row − R).
export function patchRect(centre: [number, number], radius: number): { x: number; y: number; size: number } {
  return { x: centre[1] - radius, y: centre[0] - radius, size: 2 * radius + 1 };
}

// Whether a patch centred there lies wholly inside a rows x cols image (the server checks the hole).
export function patchInside(centre: [number, number], radius: number, rows: number, cols: number): boolean {
  const [row, col] = centre;
  return row - radius >= 0 && col - radius >= 0 && row + radius < rows && col + radius < cols;
}

export type ReviewChoice = { candidate: number } | { source: [number, number] };

// The body of POST .../inpaint/review/decide.
export function decisionBody(choice: ReviewChoice): Record<string, unknown> {
  return 'candidate' in choice
    ? { candidate: choice.candidate }
    : { source: [choice.source[0], choice.source[1]] };
}
