// Evaluation of segmentation against ground truth (synthetic scans' label images): automatic strokes and the
// comparison of the two-step cut with its baselines (depth-only, colour-only, single-step RGB+D, OpenCV
// grabCut). The program segment_eval (segment/eval/) runs it over data/segment_eval/*.json and writes
// bench/results/segment.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"

namespace lidarshop {

struct EvalStrokeOptions {
  int object_erosion_cells = 4;  // the object stroke lies inside the object eroded by this many cells
  int background_margin_cells =
      12;                        // the background stroke keeps at least this distance from the object, cells
  int stroke_length_cells = 16;  // length of each (horizontal) stroke, cells
  int stroke_width_cells = 2;    // thickness, cells
  // false: both strokes anywhere in their allowed cells. true: the object stroke on the upper third of the
  // eroded object (its rows) and the background stroke below the object (rows under its lowest cell, within
  // its columns where there is room; else anywhere below it; else anywhere), as a user strokes the object
  // and the ground in front of it (the random-scene evaluation).
  bool upper_and_below = false;
};

// One short horizontal object stroke inside the eroded `truth` (CV_8U, non-zero = object) and one background
// stroke on valid cells away from it, both placed at random with `seed` (same seed = same strokes; see
// EvalStrokeOptions::upper_and_below for where). Only
// valid cells are marked. Throws InputError when the eroded object or the background margin leaves no room.
cv::Mat MakeEvalStrokes(const cv::Mat& truth, const cv::Mat& valid, uint64_t seed,
                        const EvalStrokeOptions& options = {});

struct MethodScores {
  std::string method;  // "two-step", "step-1", "depth", "color", "rgbd", "grabcut"
  MaskScores scores;
  double seconds = 0;  // wall time of the method (step-1: included in two-step)
};

// Runs every method on one scan with the same strokes and scores each against `truth` over the valid cells.
// `options.method` is ignored (all methods run); `grabcut_iterations` = 0 skips grabCut.
std::vector<MethodScores> EvaluateMethods(const Scan& scan, const cv::Mat& truth, const cv::Mat& strokes,
                                          const SegmentOptions& options, int grabcut_iterations = 5);

// One correct refinement after a two-step cut: an object stroke on the largest missed part of `truth`, or, when
// nothing is missed, a background stroke on the largest wrongly taken part, or else (the cut is exact) on the
// largest part of the background more than background_margin_cells from the object. The stroke marks only cells
// of that part (it is correct by construction), up to `stroke_length_cells` cells along the part's middle row.
struct RefinementScores {
  MaskScores before, after;
  std::string stroke;  // "object", "background" or "none" (no room for a stroke)
};
RefinementScores EvaluateRefinement(const Scan& scan, const cv::Mat& truth, const cv::Mat& strokes,
                                    const SegmentOptions& options, int stroke_length_cells = 16);

}  // namespace lidarshop
