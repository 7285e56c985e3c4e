// Strips the depth cut follows out of the picture (segment.h TrimStrips): a kerb's front face, a skirting board
// or the foot of a wall runs along the scene at about the range of an object standing by it, and its rows are
// cut off from the ground above and below by depth steps (the ground at grazing incidence changes range fast
// from row to row), so the depth-dominant cut takes the whole strip with the object it touches.
#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/cut_checks.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

cv::Mat TrimStrips(const Scan& scan, const cv::Mat& mask, const cv::Mat& object_cells,
                   const WholeObjectOptions& options) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && mask.size() == cv::Size(scan.cols, scan.rows));
  LIDARSHOP_CHECK(object_cells.type() == CV_8U && object_cells.size() == mask.size());
  if (options.strip_max_cells <= 0 || cv::countNonZero(mask) == 0) return mask.clone();
  // Opening with a vertical line removes every run of at most strip_max_cells rows: the strips, not a post
  // or a body, which are taller than they are wide.
  cv::Mat opened;
  const cv::Mat line = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(1, options.strip_max_cells + 1));
  cv::morphologyEx(mask, opened, cv::MORPH_OPEN, line);
  const cv::Mat body = StrokedParts(opened, object_cells);
  if (cv::countNonZero(body) == 0) return mask.clone();  // the strokes lie on a thin part: leave it
  // The strip's cells: the thin ones not next to the body (what they lead to, a bollard or a door, may stand
  // taller; thin parts of the object itself, a flag or a rail, join the body).
  cv::Mat near;
  cv::dilate(body, near, cv::Mat());
  const cv::Mat strip = mask & ~opened & ~near;
  if (cv::countNonZero(strip) == 0) return mask.clone();
  // Those beyond the body's box (grown by the strip's width) or along its foot (the lowest quarter of its
  // box and below) are dropped, ...
  const cv::Rect body_box = cv::boundingRect(body);
  const int k = options.strip_max_cells, foot_row = body_box.y + 3 * body_box.height / 4;
  const cv::Rect box =
      cv::Rect(body_box.x - k, body_box.y - k, body_box.width + 2 * k, body_box.height + 2 * k);
  cv::Mat dropped = strip.clone();
  for (int r = std::max(0, box.y); r < std::min(foot_row, mask.rows); ++r)
    for (int c = std::max(0, box.x); c < std::min(mask.cols, box.br().x); ++c) dropped.at<uint8_t>(r, c) = 0;
  // ... when the mask runs out of the picture (an object lies inside it: a mask that reaches two of its sides
  // holds such a strip), or when they lie at the body's foot and run farther beyond it on one side than the
  // body is wide: a strip that long along the ground line runs along the scene (a kerb), while a thin part
  // higher up is the object's own (a table's top seen edge-on above the leg the strokes lie on).
  const cv::Mat foot_strip = strip.rowRange(std::min(foot_row, mask.rows), mask.rows);
  bool along_scene = false;
  if (cv::countNonZero(foot_strip) > 0) {
    const cv::Rect foot = cv::boundingRect(foot_strip);
    along_scene = std::max(body_box.x - foot.x, foot.br().x - body_box.br().x) > body_box.width;
  }
  if (!along_scene && CheckCut(mask, cv::Mat(), WrapsInAzimuth(scan)).size() != 1) return mask.clone();
  return StrokedParts(mask & ~dropped, object_cells);
}

}  // namespace lidarshop
