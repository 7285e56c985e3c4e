// The review folder of `lidarshop inpaint --review DIR` (docs/inpaint.md "Review"): what a stopped fill hands
// the user, and the decisions made so far, so that `--resume DIR --choose N` can replay and continue.
//
// DIR/review.json   {"decisions": [{"target": [r, c], "source": [r, c]}, ...],   (made so far, in order)
//                    "review": {"review_point", "iteration", "target": [r, c], "patch_radius",
//                               "candidates": [{"index", "source": [r, c], "difference", "cluster",
//                                               "accepted", "test", "value", "threshold"}, ...],
//                               "clusters": [{"index", "representative", "members": [...]}, ...]}}
// DIR/tentative.png the fill so far with the best candidate pasted, the target patch outlined
// DIR/clusters.png  one tile per cluster: its representative source patch, 4x enlarged, in cluster order
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/inpaint.h"

namespace lidarshop::cli {

// Writes DIR (created if needed) atomically file by file. display: the result as 8-bit RGB/grey (for PNGs).
void WriteReviewFolder(const std::string& dir, const InpaintReview& review,
                       const std::vector<ReviewDecision>& decisions, const cv::Mat& tentative_display,
                       const cv::Mat& canvas_display, int patch_radius);

// Reads DIR/review.json: the decisions so far plus the pending review's target and candidate sources.
struct ReviewFolder {
  std::vector<ReviewDecision> decisions;
  Pixel target;
  std::vector<Pixel> candidates;
};
ReviewFolder ReadReviewFolder(const std::string& dir);

}  // namespace lidarshop::cli
