#include "lidarshop/scan/lazy_zeros.h"

#include <cstdlib>
#include <new>

#include <opencv2/imgproc.hpp>

namespace lidarshop {

namespace {

// OpenCV's standard allocator with calloc for fastMalloc: glibc's calloc leaves a freshly mapped chunk as the
// kernel gave it (zero pages) instead of writing it.
class CallocAllocator : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* given_data, size_t* step,
                         cv::AccessFlag /*flags*/, cv::UMatUsageFlags /*usage*/) const override {
    size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step != nullptr) {
        if (given_data != nullptr && step[i] != cv::Mat::AUTO_STEP)
          total = step[i];
        else
          step[i] = total;
      }
      total *= static_cast<size_t>(sizes[i]);
    }
    void* data = given_data != nullptr ? given_data : std::calloc(total == 0 ? 1 : total, 1);
    if (data == nullptr) throw std::bad_alloc();
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = static_cast<uchar*>(data);
    u->size = total;
    if (given_data != nullptr) u->flags |= cv::UMatData::USER_ALLOCATED;
    return u;
  }

  bool allocate(cv::UMatData* u, cv::AccessFlag /*flags*/, cv::UMatUsageFlags /*usage*/) const override {
    return u != nullptr;
  }

  void deallocate(cv::UMatData* u) const override {
    if (u == nullptr) return;
    if ((u->flags & cv::UMatData::USER_ALLOCATED) == 0) std::free(u->origdata);
    delete u;
  }
};

const cv::MatAllocator* Calloc() {
  // Never destroyed: a matrix it made may outlive any static.
  static const auto* allocator = new CallocAllocator;
  return allocator;
}

}  // namespace

cv::Mat LazyZeros(int rows, int cols, int type) {
  cv::Mat zeros;
  zeros.allocator = const_cast<cv::MatAllocator*>(Calloc());
  zeros.create(rows, cols, type);
  return zeros;
}

cv::Mat CopyOfBox(const cv::Mat& image, const cv::Rect& box) {
  cv::Mat copy = LazyZeros(image.rows, image.cols, image.type());
  const cv::Rect inside = box & cv::Rect(0, 0, image.cols, image.rows);
  if (!inside.empty()) image(inside).copyTo(copy(inside));
  return copy;
}

cv::Rect NonZeroBoxWithin(const cv::Mat& mask, const cv::Rect& within) {
  const cv::Rect inside = within & cv::Rect(0, 0, mask.cols, mask.rows);
  if (inside.empty()) return cv::Rect();
  const cv::Rect box = cv::boundingRect(mask(inside));
  return box.empty() ? cv::Rect() : box + inside.tl();
}

cv::Mat CopyOfMostlyZero(const cv::Mat& image) {
  cv::Mat copy = LazyZeros(image.rows, image.cols, image.type());
  for (int row = 0; row < image.rows; ++row)
    if (cv::countNonZero(image.row(row)) > 0) image.row(row).copyTo(copy.row(row));
  return copy;
}

}  // namespace lidarshop
