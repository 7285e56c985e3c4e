// Which target patch to fill next and from where, with acceptance (thesis ch. 7.1 "two step search" and 7.2
// "forward-looking greedy patch based inpainting"). Internal to inpaint/.
//
// Per target, with an acceptance hook:
//   1. the best `acceptance_candidates` (K) sources of the local window (local_window_radius) in ranked
//      order; the first that the acceptance accepts is taken;
//   2. if none passes, the best K of the configured search over the whole image, in ranked order (with the
//      exhaustive search, pruned: the scan of the image keeps only candidates no worse than the local K-th
//      best, which gives exactly the image's top K, since the local K are all at or below that bound);
//   3. if none passes either, the target fails (the caller falls back to the best, or asks for a review).
// Without a hook the configured search's best is taken (plain greedy filling, unchanged).
//
// Forward-looking (lookahead M > 1): the M highest-priority front pixels that have not failed are decided,
// and the one whose accepted source has the largest acceptance margin is filled; failing targets are
// deferred until a fill changes their patch, so the hole is filled from easier directions first. When all M
// fail the highest-priority front pixel is returned (failing). Decisions are cached per target and dropped
// when a fill lands within 2R of it (its known pixels changed); sources never change during a fill.
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "lidarshop/inpaint/acceptance.h"
#include "lidarshop/inpaint/fill_front.h"
#include "lidarshop/inpaint/inpaint.h"

namespace lidarshop {

struct TargetDecision {
  Pixel target;
  std::vector<SourceCandidate> candidates;  // the ranked list the choice was made from (best first)
  int chosen = -1;                          // index into candidates of the accepted one; -1 = none passed
  AcceptanceVerdict verdict;                // of the chosen candidate, or of the best when none passed
  int rejected = 0;                         // candidates the acceptance rejected
  bool passed() const { return chosen >= 0; }
};

class TargetChooser {
 public:
  // The strategies must outlive the chooser; acceptance may be null.
  TargetChooser(const InpaintCanvas& canvas, const InpaintOptions& options, const PatchDifference& difference,
                PatchSearch& search, const PatchAcceptance* acceptance, bool search_is_exhaustive);
  TargetDecision Choose(const Front& front);
  // After Ψtarget was filled.
  void Filled(Pixel target);
  // The decision for one target (cached); public for the review.
  const TargetDecision& Decide(Pixel target);
  int64_t evaluations() const { return search_.evaluations() + exhaustive_.evaluations(); }
  int global_searches() const { return global_searches_; }  // targets that needed the whole image

 private:
  TargetDecision Compute(Pixel target);
  // The best `count` sources of the smallest window of radius local_window_radius·2^i holding `count`.
  std::vector<SourceCandidate> LocalBest(const TargetDifference& difference, Pixel target, int count);

  const InpaintCanvas& canvas_;
  const InpaintOptions& options_;
  const PatchDifference& difference_;
  PatchSearch& search_;
  const PatchAcceptance* acceptance_;
  bool search_is_exhaustive_;
  ExhaustiveSearch exhaustive_;
  int global_searches_ = 0;
  std::unordered_map<int64_t, TargetDecision> cache_;  // by pixel index
};

}  // namespace lidarshop
