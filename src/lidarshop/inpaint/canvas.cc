#include "lidarshop/inpaint/canvas.h"

#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {
constexpr int kPaddingFloats = 64;  // > one AVX-512 vector past the last patch row
}  // namespace

InpaintCanvas::InpaintCanvas(const cv::Mat& image, const cv::Mat& hole_mask, int patch_radius)
    : rows_(image.rows), cols_(image.cols), channels_(image.channels()), patch_radius_(patch_radius) {
  if (image.empty()) ThrowInputError("", "", "image", "empty image");
  if (image.depth() != CV_32F || channels_ < 1 || channels_ > 16) {
    ThrowInputError("", "", "image",
                    fmt::format("expected a float image with 1..16 channels, got type {}",
                                cv::typeToString(image.type())));
  }
  if (hole_mask.type() != CV_8UC1) {
    ThrowInputError("", "", "mask",
                    fmt::format("expected an 8-bit single-channel mask, got type {}",
                                cv::typeToString(hole_mask.type())));
  }
  if (hole_mask.size() != image.size()) {
    ThrowInputError(
        "", "", "mask",
        fmt::format("mask is {}x{} but the image is {}x{}", hole_mask.cols, hole_mask.rows, cols_, rows_));
  }
  LIDARSHOP_CHECK(patch_radius_ >= 1);
  const int64_t margin_floats = (int64_t{patch_radius_} + 1) * row_stride() + kPaddingFloats;
  front_floats_ = margin_floats;
  data_.assign(static_cast<size_t>(int64_t{rows_} * cols_ * channels_ + 2 * margin_floats), 0.0f);
  known_.create(rows_, cols_, CV_8U);
  for (int r = 0; r < rows_; ++r) {
    const float* in = image.ptr<float>(r);
    const uint8_t* hole = hole_mask.ptr<uint8_t>(r);
    uint8_t* known = known_.ptr<uint8_t>(r);
    float* out = data_.data() + front_floats_ + Index(r, 0) * channels_;
    for (int c = 0; c < cols_; ++c) {
      known[c] = hole[c] == 0 ? 1 : 0;
      if (!known[c]) continue;
      for (int k = 0; k < channels_; ++k) {
        const float value = in[c * channels_ + k];
        if (!std::isfinite(value)) {
          ThrowInputError("", fmt::format("pixel (row {}, col {})", r, c), "image",
                          fmt::format("channel {} is not finite outside the hole", k));
        }
        out[c * channels_ + k] = value;
      }
    }
  }
  // Source centres: the patch's part inside the image is fully known. A box sum over the hole indicator.
  source_ = cv::Mat::zeros(rows_, cols_, CV_8U);
  source_cols_by_row_.assign(rows_, {});
  const int R = patch_radius_;
  cv::Mat hole01, integral;
  cv::compare(known_, 0, hole01, cv::CMP_EQ);
  hole01 /= 255;
  cv::integral(hole01, integral, CV_32S);
  for (int r = 0; r < rows_; ++r) {
    const int top = std::max(r - R, 0), bottom = std::min(r + R + 1, rows_);
    for (int c = 0; c < cols_; ++c) {
      const int left = std::max(c - R, 0), right = std::min(c + R + 1, cols_);
      const int holes = integral.at<int>(bottom, right) - integral.at<int>(top, right) -
                        integral.at<int>(bottom, left) + integral.at<int>(top, left);
      if (holes != 0) continue;
      source_.at<uint8_t>(r, c) = 1;
      source_cols_by_row_[r].push_back(c);
      if (r >= R && r < rows_ - R && c >= R && c < cols_ - R) source_centers_.push_back({r, c});
    }
  }
  source_pixel_.create(rows_, cols_, CV_32SC2);
  source_pixel_.setTo(cv::Scalar(-1, -1));
  fill_iteration_.create(rows_, cols_, CV_32S);
  fill_iteration_.setTo(-1);
}

cv::Rect InpaintCanvas::SourceBox(Pixel target) const {
  const int R = patch_radius_;
  // How far the target's patch sticks out of the image on each side; a source may stick out as far.
  const int top = std::max(0, R - target.row), bottom = std::max(0, target.row + R - (rows_ - 1));
  const int left = std::max(0, R - target.col), right = std::max(0, target.col + R - (cols_ - 1));
  const int row_begin = std::max(0, R - top), row_end = std::min(rows_, rows_ - R + bottom);
  const int col_begin = std::max(0, R - left), col_end = std::min(cols_, cols_ - R + right);
  return {col_begin, row_begin, std::max(0, col_end - col_begin), std::max(0, row_end - row_begin)};
}

std::vector<Pixel> InpaintCanvas::CopyPatch(Pixel target, Pixel source, int iteration) {
  LIDARSHOP_CHECK(Inside(source.row, source.col) && IsSource(source.row, source.col) &&
                  SourceFits(target, source));
  const int R = patch_radius_;
  std::vector<Pixel> filled;
  for (int dr = -R; dr <= R; ++dr) {
    for (int dc = -R; dc <= R; ++dc) {
      const int r = target.row + dr, c = target.col + dc;
      if (!Inside(r, c) || IsKnown(r, c)) continue;
      const int sr = source.row + dr, sc = source.col + dc;
      std::copy_n(PixelData(sr, sc), channels_, data_.data() + front_floats_ + Index(r, c) * channels_);
      known_.at<uint8_t>(r, c) = 1;
      source_pixel_.at<cv::Vec2i>(r, c) = cv::Vec2i(sr, sc);
      fill_iteration_.at<int>(r, c) = iteration;
      filled.push_back({r, c});
    }
  }
  return filled;
}

cv::Mat InpaintCanvas::Image() const {
  cv::Mat image(rows_, cols_, CV_32FC(channels_));
  for (int r = 0; r < rows_; ++r) std::copy_n(PixelData(r, 0), row_stride(), image.ptr<float>(r));
  return image;
}

cv::Mat ComputeFillFront(const cv::Mat& known) {
  cv::Mat front = cv::Mat::zeros(known.size(), CV_8U);
  for (int r = 0; r < known.rows; ++r) {
    for (int c = 0; c < known.cols; ++c) {
      if (known.at<uint8_t>(r, c)) continue;
      const bool next_to_known =
          (r > 0 && known.at<uint8_t>(r - 1, c)) || (r + 1 < known.rows && known.at<uint8_t>(r + 1, c)) ||
          (c > 0 && known.at<uint8_t>(r, c - 1)) || (c + 1 < known.cols && known.at<uint8_t>(r, c + 1));
      if (next_to_known) front.at<uint8_t>(r, c) = 1;
    }
  }
  return front;
}

}  // namespace lidarshop
