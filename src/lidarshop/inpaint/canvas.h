// The working state of a patch-based fill, as the pluggable strategies (priority, difference, search,
// acceptance) see it: the image being filled, which pixels are known now, which patch centres may serve as
// sources, and where every filled pixel was copied from.
//
// Pixels are addressed as (row, col) in image orientation. A patch of radius R ("half-width") centred at
// (r, c) covers rows r-R..r+R and cols c-R..c+R, i.e. (2R+1) x (2R+1) pixels. A patch may stick out of the
// image: a target's when the hole touches the border, a source's only as far as the target's does on each side
// (SourceFits), so that a target in the border rows is compared with, and copied from, cells at the same
// distance from that border (the top rows of a scan — beyond the elevation limit there is nothing — are filled
// from top rows, not from cells at least a patch radius further in).
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
  // A source centre is a pixel of the image whose patch, as far as it lies inside the image, lies outside the
  // original hole.
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

  // Pixel (0, 0); the storage extends R + 1 rows (and a SIMD vector) before and after the image, zero there,
  // so that a kernel may read whole patch rows of a source that sticks out of the image.
  const float* data() const { return data_.data() + front_floats_; }
  const float* PixelData(int row, int col) const { return data() + Index(row, col) * channels_; }

  // Known now: outside the original hole, or filled already.
  bool IsKnown(int row, int col) const { return known_.at<uint8_t>(row, col) != 0; }
  const cv::Mat& known() const { return known_; }  // H x W CV_8U, 1 = known
  // A valid source patch centre (fixed for the whole fill).
  bool IsSource(int row, int col) const { return source_.at<uint8_t>(row, col) != 0; }
  const cv::Mat& source_mask() const { return source_; }  // H x W CV_8U, 1 = source centre
  // The source centres whose patch lies wholly inside the image (they fit every target), row-major order.
  const std::vector<Pixel>& source_centers() const { return source_centers_; }
  // Per row, the columns of every source centre, border ones included (row-major order), for row-parallel
  // searches; restrict them to SourceBox(target).
  const std::vector<std::vector<int>>& source_cols_by_row() const { return source_cols_by_row_; }
  // The centres a source may have for `target`: a source patch may stick out of the image on a side only as
  // far as the target's patch does, so that every pixel of the target inside the image has its counterpart
  // inside the image. For a target whose patch lies inside the image: rows and cols R .. size − 1 − R.
  cv::Rect SourceBox(Pixel target) const;
  bool SourceFits(Pixel target, Pixel source) const {
    return SourceBox(target).contains({source.col, source.row});
  }

  // Where each filled pixel was copied from (row, col), or (-1, -1) for pixels known from the start.
  const cv::Mat& source_pixel() const { return source_pixel_; }  // H x W CV_32SC2 (row, col)
  const cv::Mat& fill_iteration() const {
    return fill_iteration_;
  }  // H x W CV_32S, -1 = known from the start

  // Copies the source patch's pixels into the unknown pixels of the target patch (inside the image), marks
  // them known and returns them. `source` must be a source centre that fits the target.
  std::vector<Pixel> CopyPatch(Pixel target, Pixel source, int iteration);

  // The filled image, H x W CV_32FC(C).
  cv::Mat Image() const;

 private:
  int rows_ = 0, cols_ = 0, channels_ = 0, patch_radius_ = 0;
  int64_t front_floats_ = 0;  // storage before pixel (0, 0)
  std::vector<float> data_;
  cv::Mat known_, source_, source_pixel_, fill_iteration_;
  std::vector<Pixel> source_centers_;
  std::vector<std::vector<int>> source_cols_by_row_;
};

// Hole pixels with at least one known 4-neighbour inside the image: the fill front (Criminisi's δΩ).
// known: H x W CV_8U, non-zero = known. Returns H x W CV_8U, 1 = front.
cv::Mat ComputeFillFront(const cv::Mat& known);

}  // namespace lidarshop
