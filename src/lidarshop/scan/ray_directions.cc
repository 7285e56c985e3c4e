#include "lidarshop/scan/ray_directions.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "lidarshop/util/parallel.h"

namespace lidarshop {

bool HasCompleteGrid(const Scan& scan) {
  return static_cast<int>(scan.grid.azimuth_rad.size()) == scan.cols &&
         static_cast<int>(scan.grid.elevation_rad.size()) == scan.rows;
}

bool HasRayDirections(const Scan& scan) { return !scan.direction.empty() || HasCompleteGrid(scan); }

cv::Mat DirectionImage(const Scan& scan) {
  if (!scan.direction.empty()) return scan.direction;
  if (!HasCompleteGrid(scan) || scan.num_cells() == 0) return {};
  return DirectionsFromGrid(scan.grid);
}

RayDirections::RayDirections(const ScanGrid& grid) : cols_(static_cast<int>(grid.azimuth_rad.size())) {
  sin_azimuth_.resize(grid.azimuth_rad.size());
  cos_azimuth_.resize(grid.azimuth_rad.size());
  for (size_t col = 0; col < grid.azimuth_rad.size(); ++col) {
    sin_azimuth_[col] = std::sin(grid.azimuth_rad[col]);
    cos_azimuth_[col] = std::cos(grid.azimuth_rad[col]);
  }
  cos_elevation_.resize(grid.elevation_rad.size());
  sin_elevation_.resize(grid.elevation_rad.size());
  for (size_t row = 0; row < grid.elevation_rad.size(); ++row) {
    cos_elevation_[row] = std::cos(grid.elevation_rad[row]);
    sin_elevation_[row] = static_cast<float>(std::sin(grid.elevation_rad[row]));
  }
}

RayDirections::RayDirections(const Scan& scan) : cols_(scan.cols) {
  if (!scan.direction.empty()) {
    image_ = scan.direction;
    return;
  }
  if (!HasCompleteGrid(scan))
    throw std::logic_error("RayDirections: the scan holds no directions and no grid");
  *this = RayDirections(scan.grid);
}

bool ReleaseGridDirections(Scan* scan) {
  if (scan->direction.empty()) return HasCompleteGrid(*scan);
  if (!HasCompleteGrid(*scan)) return false;
  const RayDirections from_grid(scan->grid);
  std::atomic<bool> same{true};
  ParallelFor(scan->rows, [&](int64_t r) {
    if (!same.load(std::memory_order_relaxed)) return;
    const int row = static_cast<int>(r);
    const cv::Vec3f* held = scan->direction.ptr<cv::Vec3f>(row);
    for (int col = 0; col < scan->cols; ++col) {
      const cv::Vec3f expected = from_grid(row, col);
      if (std::memcmp(&held[col], &expected, sizeof(expected)) != 0) {
        same = false;
        return;
      }
    }
  });
  if (same) scan->direction.release();
  return same;
}

Scan MakeScanWithoutDirections(int rows, int cols, bool with_color, bool with_intensity) {
  if (rows < 0 || cols < 0) throw std::logic_error("MakeScanWithoutDirections: negative size");
  Scan scan;
  scan.rows = rows;
  scan.cols = cols;
  scan.valid = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  scan.range = cv::Mat(rows, cols, CV_32F, cv::Scalar(0));
  scan.point = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
  if (with_intensity) scan.intensity = cv::Mat(rows, cols, CV_32F, cv::Scalar(0.5));
  if (with_color) scan.color = cv::Mat(rows, cols, CV_8UC3, cv::Scalar::all(0));
  return scan;
}

}  // namespace lidarshop
