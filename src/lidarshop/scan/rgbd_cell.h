// One cell of RgbdImage (scan.h): for callers that read a few cells of a large scan (the segmentation's graph
// nodes) instead of the whole CV_32FC4 picture. Inline: it sits in per-cell loops.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// R, G, B in [0, 1] (grey intensity without colour, 0 without either) and the range in metres of one cell.
inline cv::Vec4f RgbdAt(const Scan& scan, int row, int col) {
  cv::Vec4f out(0.f, 0.f, 0.f, 0.f);
  if (!scan.color.empty()) {
    const cv::Vec3b& c = scan.color.at<cv::Vec3b>(row, col);
    out = cv::Vec4f(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f, 0.f);
  } else if (!scan.intensity.empty()) {
    const float gray = scan.intensity.at<float>(row, col);
    out = cv::Vec4f(gray, gray, gray, 0.f);
  }
  out[3] = scan.range.at<float>(row, col);
  return out;
}

}  // namespace lidarshop
