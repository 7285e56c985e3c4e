// Source-patch searches: given a target patch and a patch difference, return the best source centres.
//
// Every search returns candidates in ascending difference, ties broken by (row, col), so that results never
// depend on the thread count. Exhaustive and local searches are exact over their candidate sets; two-step is
// exact when global_gain = 1; PatchMatch is approximate (InpaintResult and bench/inpaint_bench.cc report how
// often it finds the exhaustive answer and the SSD ratio when it does not).
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/inpaint/patch_difference.h"

namespace lidarshop {

struct SourceCandidate {
  Pixel source;
  float difference = std::numeric_limits<float>::infinity();
};

// Strict weak order: smaller difference first, then smaller (row, col).
bool CandidateBefore(const SourceCandidate& a, const SourceCandidate& b);

// Sorts by CandidateBefore, keeps each source once and at most `count`.
void MergeCandidates(std::vector<SourceCandidate>& candidates, int count);

class PatchSearch {
 public:
  virtual ~PatchSearch() = default;
  // Up to `count` best source centres for `target` (fewer only if the canvas has fewer). Not thread-safe (may
  // keep state between queries); may evaluate candidates in parallel internally.
  virtual std::vector<SourceCandidate> Find(const InpaintCanvas& canvas, const TargetDifference& difference,
                                            Pixel target, int count) = 0;
  // Candidate differences evaluated so far (including early-terminated ones).
  int64_t evaluations() const { return evaluations_.load(); }

 protected:
  std::atomic<int64_t> evaluations_{0};
};

// Every source centre of the image. Parallel over source rows, scanned from the middle of the range outwards
// (nearby sources first); each chunk keeps its own top-k and the chunks share one early-termination bound, the
// least k-th best of any chunk so far (>= the k-th best of the whole range, so no answer is ever pruned; the
// merge is exact), so the answer is the same for any number of threads and scheduling.
class ExhaustiveSearch : public PatchSearch {
 public:
  std::vector<SourceCandidate> Find(const InpaintCanvas& canvas, const TargetDifference& difference,
                                    Pixel target, int count) override;
  // The best `count` of the source centres within `radius` (Chebyshev) of the target: the (4R+3)² window
  // around it is scanned first and its count-th best bounds the scan of the rest (exact).
  std::vector<SourceCandidate> FindNear(const InpaintCanvas& canvas, const TargetDifference& difference,
                                        Pixel target, int count, int radius);
  // The best `count` of the source centres in rows [row_begin, row_end) and cols [col_begin, col_end) that fit
  // the target (InpaintCanvas::SourceBox), with an initial early-termination bound: candidates with
  // difference > bound may be left out.
  std::vector<SourceCandidate> FindBelow(const InpaintCanvas& canvas, const TargetDifference& difference,
                                         Pixel target, int count, float bound, int row_begin, int row_end,
                                         int col_begin, int col_end);
};

// Source centres within a (2·window_radius+1)² window around the target; falls back to the whole image when
// the window holds none.
class LocalSearch : public PatchSearch {
 public:
  explicit LocalSearch(int window_radius) : window_radius_(window_radius) {}
  std::vector<SourceCandidate> Find(const InpaintCanvas& canvas, const TargetDifference& difference,
                                    Pixel target, int count) override;

 private:
  int window_radius_;
  ExhaustiveSearch exhaustive_;
};

// Local first, then global: the local window's best k set an early-termination bound (divided by
// global_gain) for the scan of the whole image, and global candidates are ranked by
// difference·global_gain against local ones. global_gain = 1 gives exactly the exhaustive answer, only
// faster; > 1 prefers nearby sources (coherence).
class TwoStepSearch : public PatchSearch {
 public:
  TwoStepSearch(int window_radius, double global_gain)
      : window_radius_(window_radius), global_gain_(global_gain) {}
  std::vector<SourceCandidate> Find(const InpaintCanvas& canvas, const TargetDifference& difference,
                                    Pixel target, int count) override;

 private:
  int window_radius_;
  double global_gain_;
  ExhaustiveSearch exhaustive_;
};

struct PatchMatchOptions {
  int random_samples = 48;  // uniformly drawn source centres per query
  int local_samples = 32;   // draws within local_radius of the target (nearby sources are often coherent)
  int local_radius = 40;    // pixels
  int iterations = 4;       // rounds of propagation + random search around the best so far
  double alpha = 0.5;       // radius ratio of successive random-search samples (Barnes et al. 2009, §3.2)
  uint64_t seed = 0;
  void Check() const;
};

// PatchMatch (Barnes, Shechtman, Finkelstein, Goldman 2009) adapted to the greedy fill, per query:
//  * propagation: the offsets of already-filled pixels of the target patch (q came from s(q), so the
//    target may come from s(q) − (q − p)) and of the patches filled last, plus ±1-pixel moves of the
//    current best;
//  * random search: samples around the current best at radii max(H, W)·αⁱ down to 1 pixel;
//  * `random_samples` uniform draws over the image and `local_samples` draws near the target.
// The random stream is seeded from (seed, target); the search runs on one thread, so the fill
// is a deterministic function of (inputs, seed). It remembers the offsets of its last
// answers: use a fresh object per fill.
class PatchMatchSearch : public PatchSearch {
 public:
  explicit PatchMatchSearch(PatchMatchOptions options);
  std::vector<SourceCandidate> Find(const InpaintCanvas& canvas, const TargetDifference& difference,
                                    Pixel target, int count) override;

 private:
  PatchMatchOptions options_;
  std::vector<cv::Point> recent_offsets_;  // (dcol, drow) of the last few chosen fills
};

}  // namespace lidarshop
