#include "lidarshop/segment/cut_checks.h"

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgproc.hpp>

namespace lidarshop {

cv::Mat StrokedParts(const cv::Mat& mask, const cv::Mat& object_strokes) {
  CV_Assert(mask.type() == CV_8U && object_strokes.type() == CV_8U && mask.size() == object_strokes.size());
  cv::Mat labels;
  const int count = cv::connectedComponents(mask != 0, labels, 8, CV_32S);
  std::vector<uint8_t> stroked(static_cast<size_t>(count), 0);
  for (int row = 0; row < mask.rows; ++row) {
    const int32_t* label = labels.ptr<int32_t>(row);
    const uint8_t* stroke = object_strokes.ptr<uint8_t>(row);
    for (int col = 0; col < mask.cols; ++col)
      if (stroke[col] != 0 && label[col] != 0) stroked[static_cast<size_t>(label[col])] = 1;
  }
  cv::Mat parts(mask.size(), CV_8U, cv::Scalar(0));
  for (int row = 0; row < mask.rows; ++row) {
    const int32_t* label = labels.ptr<int32_t>(row);
    uint8_t* out = parts.ptr<uint8_t>(row);
    for (int col = 0; col < mask.cols; ++col)
      if (label[col] != 0 && stroked[static_cast<size_t>(label[col])]) out[col] = 255;
  }
  return parts;
}

bool WrapsInAzimuth(const Scan& scan) {
  const std::vector<double>& azimuth = scan.grid.azimuth_rad;
  if (azimuth.size() < 2) return false;
  const double step = (azimuth.back() - azimuth.front()) / static_cast<double>(azimuth.size() - 1);
  // The span plus one column's step closes the circle (to half a step).
  return std::abs(azimuth.back() - azimuth.front() + step - 2 * M_PI) < 0.5 * std::abs(step);
}

std::vector<std::string> CheckCut(const cv::Mat& cut, const cv::Mat& stroked_part, bool wraps_in_azimuth) {
  std::vector<std::string> warnings;
  if (cut.empty()) return warnings;
  const int64_t cells = cv::countNonZero(cut);
  if (cells == 0) return warnings;
  if (!stroked_part.empty()) {
    const int64_t part = cv::countNonZero(stroked_part);
    const int64_t added = cv::countNonZero((cut != 0) & (stroked_part == 0));
    if (part > 0 && static_cast<double>(added) > kCutGrowthLimit * static_cast<double>(part)) {
      warnings.push_back(
          fmt::format("the cut grew {} cells past the {} cells of the part its object strokes lie on, {:.1f} "
                      "times that part "
                      "(more than {:g}): it may have leaked into the ground or a neighbour; add background "
                      "strokes where it "
                      "leaked",
                      added, part, static_cast<double>(added) / static_cast<double>(part), kCutGrowthLimit));
    }
  }
  const cv::Mat in = cut != 0;
  std::vector<std::string> sides;
  if (cv::countNonZero(in.row(0)) > 0) sides.push_back("top");
  if (cv::countNonZero(in.row(in.rows - 1)) > 0) sides.push_back("bottom");
  const bool left = cv::countNonZero(in.col(0)) > 0, right = cv::countNonZero(in.col(in.cols - 1)) > 0;
  if (wraps_in_azimuth) {
    if (left || right) sides.push_back("left/right seam");
  } else {
    if (left) sides.push_back("left");
    if (right) sides.push_back("right");
  }
  if (sides.size() >= 2) {
    warnings.push_back(fmt::format(
        "the cut ({} cells) touches the {} borders of the scan's image: an object lies inside the "
        "picture, so it may hold the ground, a wall or the sky's edge; check the overlay",
        cells, fmt::join(sides, ", ")));
  }
  return warnings;
}

}  // namespace lidarshop
