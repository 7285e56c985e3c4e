// Checks of a finished cut that say when it looks wrong. The cut is kept as it is; the checks give one
// sentence each, in SegmentResult::warnings (the CLI prints them, the server and --json return them).
//
//   - growth: the cut grew past the part its object strokes lie on by more than kCutGrowthLimit times that
//     part's cells. Two-step: the part is the 8-connected parts of the depth-dominant step-1 cut that hold an
//     object stroke cell (a strict subset of the object where it stands out in depth), grown over the cells
//     continuous with them in depth and orientation (GrowWholeObject, without its leak limit): the object as
//     the scan's geometry outlines it. A cut that grew far past that has usually leaked along the ground or
//     into a neighbour of the same colour (a box on a floor cut as the pump beside it).
//   - border: the cut touches two sides of the scan's image (top, bottom, left, right; on a full 360° scan
//     left and right are one seam). Objects lie inside the picture; a cut reaching two sides holds the ground,
//     a wall or the sky's edge.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// A cut that adds more than this many times its strokes' part's cells beyond it is reported (dimensionless;
// as WholeObjectOptions::max_growth counts growth).
inline constexpr double kCutGrowthLimit = 3.0;

// The 8-connected parts of `mask` (CV_8U, non-zero = in) that hold a cell of `object_strokes` (CV_8U,
// non-zero = an object stroke cell), the same size. CV_8U 255/0.
cv::Mat StrokedParts(const cv::Mat& mask, const cv::Mat& object_strokes);

// True when the scan's columns cover the whole circle (the first and last columns are neighbours).
bool WrapsInAzimuth(const Scan& scan);

// The warnings about `cut` (CV_8U rows x cols, non-zero = object). `stroked_part`: the part of the object its
// strokes lie on (see above); empty = no growth check (the single-cut methods have no
// depth-dominant cut to compare with). `wraps_in_azimuth`: see WrapsInAzimuth.
std::vector<std::string> CheckCut(const cv::Mat& cut, const cv::Mat& stroked_part, bool wraps_in_azimuth);

}  // namespace lidarshop
