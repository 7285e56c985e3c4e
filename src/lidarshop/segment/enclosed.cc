// No-return cells inside an object's outline (segment.h): a laser finds no echo on dark hair, black rubber or
// glass, so these cells are holes in a cut that only covers cells with a return.
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

cv::Mat EnclosedNoReturnCells(const cv::Mat& mask, const cv::Mat& valid) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && valid.type() == CV_8U && mask.size() == valid.size());
  const cv::Mat no_return = valid == 0;
  cv::Mat component;
  const int count = cv::connectedComponents(no_return, component, 4, CV_32S);
  // A component is open when it reaches the image border (the scan's edge: nothing says what lies beyond)
  // or touches a cell with a return that is not object.
  std::vector<uint8_t> open(static_cast<size_t>(count), 0);
  const int rows = mask.rows, cols = mask.cols;
  for (int r = 0; r < rows; ++r) {
    const int32_t* label = component.ptr<int32_t>(r);
    for (int c = 0; c < cols; ++c) {
      if (label[c] == 0) continue;  // a cell with a return
      uint8_t& is_open = open[static_cast<size_t>(label[c])];
      if (is_open) continue;
      if (r == 0 || c == 0 || r == rows - 1 || c == cols - 1) {
        is_open = 1;
        continue;
      }
      constexpr int kDr[4] = {-1, 1, 0, 0}, kDc[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int rr = r + kDr[k], cc = c + kDc[k];
        if (valid.at<uint8_t>(rr, cc) != 0 && mask.at<uint8_t>(rr, cc) == 0) is_open = 1;
      }
    }
  }
  cv::Mat enclosed = cv::Mat::zeros(mask.size(), CV_8U);
  for (int r = 0; r < rows; ++r) {
    const int32_t* label = component.ptr<int32_t>(r);
    uint8_t* out = enclosed.ptr<uint8_t>(r);
    for (int c = 0; c < cols; ++c)
      if (label[c] != 0 && !open[static_cast<size_t>(label[c])]) out[c] = 255;
  }
  return enclosed;
}

}  // namespace lidarshop
