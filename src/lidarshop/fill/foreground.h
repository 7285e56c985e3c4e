// What stands in front of the hole's background (issue 30, class 5).
//
// The hole behind a removed object shows the background that continues behind it: the wall, the ground, the
// kerb. Other objects near it — a person beside the removed one, a bench, a crate touching it — stand in front
// of that background. Their patches copied into the hole float (a person-shaped collage at the person's depth
// in front of the wall), and their ranges on the hole's rim pull the reconstruction forward. So the fill first
// finds the known cells that stand in front of the surface behind them:
//   * along each row of the scan (a scan's rows are elevations: the ground keeps its range along a row, a wall
//     changes it smoothly, an object standing on either is a run of cells bounded by depth jumps), a run of
//     known cells without a depth jump inside (neighbours more than 0.1 m + `jump_ratio` × range apart: a
//     person 3 m before a wall 35 m away is one, a wall seen at 84° from its normal is not), at most
//     `reach_cells` long, whose neighbours beyond both ends lie farther by such a jump or have no return over 8
//     cells or more (sky behind a post; fewer are a dropout, passed like the hole), is in front;
//   * a run that ends at the hole is judged by the first known cell beyond the hole's cells in that row: a
//     person touching the removed object has the wall beyond it on both sides, the wall between the legs of a
//     removed table has the same wall beyond the legs and is not in front;
//   * the scan's border is no evidence: a run that reaches it is not in front.
// The fill then treats the front cells touching the hole as part of the hole (they are filled with the
// background behind them, which is not written: only the hole's own cells are) and takes no patch that would
// copy a front cell (fill/foreground.h's acceptance in fill.cc).
#pragma once

#include <opencv2/core.hpp>

namespace lidarshop::fill_internal {

// CV_8U rows x cols, 255 = a known cell in front of the surface behind it. `range` CV_32F (0 without a
// return), `known_valid` CV_8U (outside the hole with a return), `hole` CV_8U non-zero = hole.
cv::Mat FrontCells(const cv::Mat& range, const cv::Mat& known_valid, const cv::Mat& hole, double jump_ratio,
                   int reach_cells);

// The front cells (CV_8U) whose 8-connected part touches the hole and whose mean range (`range`, CV_32F) is at
// most `max_range_m` — a neighbour standing beside the removed object is about as near as it; a wall behind it
// that merely stands before a farther wall is not taken — grown by `margin_cells` over known cells (mixed cells
// at their silhouettes belong to neither surface). CV_8U 255/0, never a hole cell.
cv::Mat FrontTouchingHole(const cv::Mat& front, const cv::Mat& range, const cv::Mat& hole,
                          const cv::Mat& known_valid, double max_range_m, int margin_cells);

}  // namespace lidarshop::fill_internal
