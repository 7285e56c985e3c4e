#include "lidarshop/poisson/operators.h"

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

cv::Mat ToFloat(const cv::Mat& image) {
  if (image.depth() == CV_32F || image.depth() == CV_64F) return image;
  cv::Mat converted;
  image.convertTo(converted, CV_32F);
  return converted;
}

template <typename T>
void GradientRows(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy) {
  const int rows = image.rows, cols = image.cols, n = image.channels();
  for (int y = 0; y < rows; ++y) {
    const T* row = image.ptr<T>(y);
    const T* below = y + 1 < rows ? image.ptr<T>(y + 1) : nullptr;
    T* out_x = gx.ptr<T>(y);
    T* out_y = gy.ptr<T>(y);
    for (int i = 0; i < cols * n; ++i) {
      out_x[i] = i + n < cols * n ? row[i + n] - row[i] : T(0);
      out_y[i] = below ? below[i] - row[i] : T(0);
    }
  }
}

template <typename T>
void DivergenceRows(const cv::Mat& gx, const cv::Mat& gy, cv::Mat& div) {
  const int rows = gx.rows, cols = gx.cols, n = gx.channels();
  for (int y = 0; y < rows; ++y) {
    const T* row_x = gx.ptr<T>(y);
    const T* row_y = gy.ptr<T>(y);
    const T* above_y = y > 0 ? gy.ptr<T>(y - 1) : nullptr;
    T* out = div.ptr<T>(y);
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < n; ++c) {
        const int i = x * n + c;
        const T right = x + 1 < cols ? row_x[i] : T(0);  // edge (x, x+1); leaves the image in the last column
        const T left = x > 0 ? row_x[i - n] : T(0);      // edge (x−1, x)
        const T down = y + 1 < rows ? row_y[i] : T(0);
        const T up = above_y ? above_y[i] : T(0);
        out[i] = (right - left) + (down - up);
      }
    }
  }
}

}  // namespace

ImageGradient ForwardGradient(const cv::Mat& image_in) {
  if (image_in.empty()) throw InputError("ForwardGradient: empty image");
  const cv::Mat image = ToFloat(image_in);
  ImageGradient gradient;
  gradient.gx.create(image.size(), image.type());
  gradient.gy.create(image.size(), image.type());
  if (image.depth() == CV_64F) {
    GradientRows<double>(image, gradient.gx, gradient.gy);
  } else {
    GradientRows<float>(image, gradient.gx, gradient.gy);
  }
  return gradient;
}

cv::Mat BackwardDivergence(const cv::Mat& gx, const cv::Mat& gy) {
  if (gx.empty() || gy.empty()) throw InputError("BackwardDivergence: empty gradient image");
  if (gx.size() != gy.size() || gx.type() != gy.type()) {
    throw InputError(fmt::format("BackwardDivergence: gx ({}x{}, type {}) and gy ({}x{}, type {}) differ",
                                 gx.cols, gx.rows, gx.type(), gy.cols, gy.rows, gy.type()));
  }
  if (gx.depth() != CV_32F && gx.depth() != CV_64F) {
    throw InputError("BackwardDivergence: gradients must be CV_32F or CV_64F");
  }
  cv::Mat div(gx.size(), gx.type());
  if (gx.depth() == CV_64F) {
    DivergenceRows<double>(gx, gy, div);
  } else {
    DivergenceRows<float>(gx, gy, div);
  }
  return div;
}

cv::Mat Laplacian5(const cv::Mat& image) {
  const ImageGradient gradient = ForwardGradient(image);
  return BackwardDivergence(gradient.gx, gradient.gy);
}

}  // namespace lidarshop
