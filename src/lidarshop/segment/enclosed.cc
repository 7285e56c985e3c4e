// No-return cells inside an object's outline (segment.h): a laser finds no echo on dark hair, black rubber or
// glass, so these cells are holes in a cut that only covers cells with a return.
#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

cv::Mat EnclosedNoReturnCells(const cv::Mat& mask, const cv::Mat& valid) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && valid.type() == CV_8U && mask.size() == valid.size());
  // Flood the outside of the mask from every border cell (4-connected); what stays unflooded is enclosed.
  // Cells with a return seen through the object (inside a car through its window) stay enclosed too, so the
  // no-return cells around them are still offered.
  cv::Mat outside = (mask == 0) / 255;  // 1 = not the object
  cv::Mat padded;
  cv::copyMakeBorder(outside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(1));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(2), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
  const cv::Mat inner = padded(cv::Rect(1, 1, mask.cols, mask.rows)) == 1;  // outside the mask, not reached
  return inner & (valid == 0);
}

}  // namespace lidarshop
