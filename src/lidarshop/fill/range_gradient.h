// Range-image pieces of the hole fill: gradients with one-sided differences, the nearest known cell, and the
// guidance field restricted to cells with data.
#pragma once

#include <opencv2/core.hpp>

namespace lidarshop::fill_internal {

// Forward differences of `range` (CV_32F) at every `usable` cell (CV_8U, non-zero = known with a return):
//   gx(y, x) = r(y, x+1) − r(y, x)    when (y, x+1) is usable,
//            = r(y, x) − r(y, x−1)    else when (y, x−1) is usable (one-sided),
//            = 0                      else;
// likewise gy downwards. Cells that are not usable get 0. Metres per cell, CV_32F.
struct RangeGradient {
  cv::Mat gx, gy;
};
RangeGradient OneSidedRangeGradient(const cv::Mat& range, const cv::Mat& usable);

// For every cell of `hole` (CV_8U, non-zero), the nearest cell outside it in 4-connected steps
// (breadth-first, ties in a fixed order, so the answer does not depend on threads). CV_32SC2 (row, col),
// (−1, −1) outside the hole and for hole cells that no known cell reaches.
cv::Mat NearestKnownCell(const cv::Mat& hole);

// Depth discontinuities between usable neighbours: right(y, x) / down(y, x) = 255 where the edge to (y, x+1)
// / (y+1, x) joins two usable cells whose ranges differ by more than `ratio` times the nearer one (0 = none).
// CV_8U rows x cols each.
struct EdgeMasks {
  cv::Mat right, down;
};
EdgeMasks DepthJumps(const cv::Mat& range, const cv::Mat& usable, double ratio);

// The guidance field (gx, gy) with every edge that touches a cell without data (`no_data`, CV_8U non-zero)
// or is cut (`cuts`, may be empty) set to 0, so that its divergence matches a Poisson system that leaves
// those edges out. Returns the divergence, CV_64F.
cv::Mat GuidanceDivergence(const cv::Mat& gx, const cv::Mat& gy, const cv::Mat& no_data,
                           const EdgeMasks& cuts = {});

// Cells of `domain` (CV_8U) that reach no `anchor` cell (CV_8U) through 4-neighbour edges that are not cut:
// such parts have no known range to start from. CV_8U 255/0.
cv::Mat UnanchoredCells(const cv::Mat& domain, const cv::Mat& anchor, const EdgeMasks& cuts = {});

// A robust scale of a channel: the `quantile` (0..1) of |values| over the non-zero cells of `where`; `floor`
// when there are none or the quantile is smaller.
double AbsQuantile(const cv::Mat& values, const cv::Mat& where, double quantile, double floor);

// Hole cells (`hole` CV_8U non-zero) whose nearest known cells to the left and to the right in the same row both
// lack a return (`known_valid` CV_8U zero) and belong to regions without a return that reach the image's border
// (8-connected): CV_8U 255. The sky beside a lamp post and the band beyond the far end of the ground qualify; a
// stereo cloud's dropouts and an object's own occlusion shadow beside a table-top hole do not (the mug of the
// shared RGB-D cloud: bars of 136–164 cells across the table left empty). A hole run touching the image's side is
// never marked.
cv::Mat NoReturnOnBothSides(const cv::Mat& hole, const cv::Mat& known_valid);

// Adds to `cuts` the seams between copies: an edge touching the hole whose two cells do not show two neighbouring
// cells (`source` CV_32SC2 gives the cell each hole cell shows; a known cell shows itself) is cut where the
// ranges (`range` CV_32F, 0 = no return) of the cells they show differ by more than `ratio` times the nearer.
void SeamCuts(const cv::Mat& range, const cv::Mat& hole, const cv::Mat& source, double ratio,
              EdgeMasks* cuts);

}  // namespace lidarshop::fill_internal
