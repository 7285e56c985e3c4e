// No-return cells inside an object's outline (segment.h): a laser finds no echo on dark hair, black rubber or
// glass, so these cells are holes in a cut that only covers cells with a return.
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/lazy_zeros.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

// The enclosed no-return cells of `mask` within its bounding box `box` (CV_8U 255/0, the box's size). Every
// cell outside the box is reachable from the image border, and so is the ring of cells around the box (none
// is the object's), so the flood needs only the box and that ring: the work and the memory follow the
// object, not the scan.
cv::Mat EnclosedInBox(const cv::Mat& mask, const cv::Mat& valid, const cv::Rect& box) {
  // 1 = not the object; the ring (and anything beyond the image) is outside.
  cv::Mat padded(box.height + 2, box.width + 2, CV_8U, cv::Scalar(1));
  for (int row = 0; row < box.height; ++row) {
    const uint8_t* m = mask.ptr<uint8_t>(box.y + row) + box.x;
    uint8_t* out = padded.ptr<uint8_t>(row + 1) + 1;
    for (int col = 0; col < box.width; ++col) out[col] = m[col] == 0 ? 1 : 0;
  }
  // Cells with a return seen through the object (inside a car through its window) stay enclosed too, so the
  // no-return cells around them are still offered.
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(2), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
  cv::Mat enclosed(box.height, box.width, CV_8U);
  for (int row = 0; row < box.height; ++row) {
    const uint8_t* p = padded.ptr<uint8_t>(row + 1) + 1;
    const uint8_t* v = valid.ptr<uint8_t>(box.y + row) + box.x;
    uint8_t* out = enclosed.ptr<uint8_t>(row);
    for (int col = 0; col < box.width; ++col) out[col] = p[col] == 1 && v[col] == 0 ? 255 : 0;
  }
  return enclosed;
}

}  // namespace

cv::Mat EnclosedNoReturnCells(const cv::Mat& mask, const cv::Mat& valid) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && valid.type() == CV_8U && mask.size() == valid.size());
  cv::Mat enclosed = LazyZeros(mask.rows, mask.cols, CV_8U);
  const cv::Rect box = cv::boundingRect(mask);
  if (!box.empty()) EnclosedInBox(mask, valid, box).copyTo(enclosed(box));
  return enclosed;
}

void AddEnclosedNoReturnCells(const cv::Mat& valid, cv::Mat* mask) {
  AddEnclosedNoReturnCells(valid, cv::Rect(0, 0, mask->cols, mask->rows), mask);
}

void AddEnclosedNoReturnCells(const cv::Mat& valid, const cv::Rect& mask_box, cv::Mat* mask) {
  LIDARSHOP_CHECK(mask->type() == CV_8U && valid.type() == CV_8U && mask->size() == valid.size());
  const cv::Rect box = NonZeroBoxWithin(*mask, mask_box);
  if (box.empty()) return;
  cv::Mat in_box = (*mask)(box);
  in_box |= EnclosedInBox(*mask, valid, box);
}

}  // namespace lidarshop
