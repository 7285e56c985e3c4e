// QuickShift (Vedaldi and Soatto, "Quick Shift and Kernel Methods for Mode Seeking", ECCV 2008): mode
// seeking in the joint space of image position and feature values, without iterations.
//
//   1. Density: E(p) = Σ_q exp(−d(p, q)² / (2σ²)) over the cells q within 3σ of p (positions in cells), where
//      d² = |pos(p) − pos(q)|² + |f(p) − f(q)|² (the features carry their own scale).
//   2. Each cell links to the nearest cell (by d) of higher density within the window, when d < max_dist;
//      cells without such a neighbour are roots (the modes).
//   3. A segment is a tree: every cell takes the label of its root.
// Ties in density are broken by cell index, so the forest has no cycles and the result does not depend on
// the thread count. Written by hand: no library in Debian has it (OpenCV ximgproc has SLIC, SEEDS, LSC and
// graph segmentation; VLFeat and scikit-image are not C++ libraries packaged here).
#pragma once

#include <opencv2/core.hpp>

namespace lidarshop {

struct QuickShiftOptions {
  double kernel_size = 3.0;  // σ of the density kernel, cells (joint-space units), > 0
  double max_dist = 10.0;    // longest link, joint-space units, > 0
};

// features: CV_32FC(n), n >= 1, already scaled; mask: CV_8U of the same size, non-zero = take part (empty =
// all). Returns CV_32S labels 0..count−1 for the masked cells, −1 elsewhere, numbered in row-major order of
// their roots.
cv::Mat QuickShift(const cv::Mat& features, const cv::Mat& mask, const QuickShiftOptions& options,
                   int* count = nullptr);

}  // namespace lidarshop
