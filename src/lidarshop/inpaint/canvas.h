// The working state of a patch-based fill, as the pluggable strategies (priority, difference, search,
// acceptance) see it: the image being filled, which pixels are known now, which patch centres may serve as
// sources, and where every filled pixel was copied from.
//
// Pixels are addressed as (row, col) in image orientation. A patch of radius R ("half-width") centred at
// (r, c) covers rows r-R..r+R and cols c-R..c+R, i.e. (2R+1) x (2R+1) pixels; a target patch may stick out of
// the image (holes touching the border), a source patch never does.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace lidarshop {

struct Pixel {
  int row = 0;
  int col = 0;
  friend bool operator==(const Pixel&, const Pixel&) = default;
};

// The image being filled: H x W x C floats, row-major and interleaved, with hole pixels set to 0 until filled
// and padding after the last pixel so that SIMD loops may read a few floats past a patch row.
class InpaintCanvas {
 public:
  // image: H x W CV_32FC(C), C in 1..16, finite outside the hole. hole_mask: H x W CV_8U, non-zero = hole.
  // A source centre is a pixel whose whole patch lies inside the image and outside the original hole.
  // Throws InputError on mismatched sizes, wrong types or non-finite known pixels.
  InpaintCanvas(const cv::Mat& image, const cv::Mat& hole_mask, int patch_radius);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int channels() const { return channels_; }
  int patch_radius() const { return patch_radius_; }
  int64_t row_stride() const {
    return int64_t{cols_} * channels_;
  }  // floats between vertically adjacent pixels
  bool Inside(int row, int col) const { return row >= 0 && row < rows_ && col >= 0 && col < cols_; }
  int64_t Index(int row, int col) const { return int64_t{row} * cols_ + col; }

  const float* data() const { return data_.data(); }
  const float* PixelData(int row, int col) const { return data_.data() + Index(row, col) * channels_; }

  // Known now: outside the original hole, or filled already.
  bool IsKnown(int row, int col) const { return known_.at<uint8_t>(row, col) != 0; }
  const cv::Mat& known() const { return known_; }  // H x W CV_8U, 1 = known
  // A valid source patch centre (fixed for the whole fill).
  bool IsSource(int row, int col) const { return source_.at<uint8_t>(row, col) != 0; }
  const cv::Mat& source_mask() const { return source_; }  // H x W CV_8U, 1 = source centre
  const std::vector<Pixel>& source_centers() const { return source_centers_; }  // row-major order
  // Per row, the source-centre columns (row-major order), for row-parallel searches.
  const std::vector<std::vector<int>>& source_cols_by_row() const { return source_cols_by_row_; }

  // Where each filled pixel was copied from (row, col), or (-1, -1) for pixels known from the start.
  const cv::Mat& source_pixel() const { return source_pixel_; }  // H x W CV_32SC2 (row, col)
  const cv::Mat& fill_iteration() const {
    return fill_iteration_;
  }  // H x W CV_32S, -1 = known from the start

  // Copies the source patch's pixels into the unknown pixels of the target patch (inside the image), marks
  // them known and returns them. `source` must be a source centre.
  std::vector<Pixel> CopyPatch(Pixel target, Pixel source, int iteration);

  // The filled image, H x W CV_32FC(C).
  cv::Mat Image() const;

 private:
  int rows_ = 0, cols_ = 0, channels_ = 0, patch_radius_ = 0;
  std::vector<float> data_;
  cv::Mat known_, source_, source_pixel_, fill_iteration_;
  std::vector<Pixel> source_centers_;
  std::vector<std::vector<int>> source_cols_by_row_;
};

// Hole pixels with at least one known 4-neighbour inside the image: the fill front (Criminisi's δΩ).
// known: H x W CV_8U, non-zero = known. Returns H x W CV_8U, 1 = front.
cv::Mat ComputeFillFront(const cv::Mat& known);

}  // namespace lidarshop
