// Internal to the site module: where a direction of a station's scanner frame falls on its grid (the
// nearest cell), and the small-region filter of a grid mask; shared by the transient test and the fill from
// other stations.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// `mask` (CV_8U) without its 8-connected regions smaller than `min_cells`: 255 where a kept region is.
inline cv::Mat WithoutSmallRegions(const cv::Mat& mask, int min_cells) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<uint8_t> keep(count, 0);
  for (int i = 1; i < count; ++i) keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= min_cells ? 255 : 0;
  cv::Mat out(mask.size(), CV_8U);
  for (int r = 0; r < mask.rows; ++r) {
    const int32_t* l = labels.ptr<int32_t>(r);
    uint8_t* o = out.ptr<uint8_t>(r);
    for (int c = 0; c < mask.cols; ++c) o[c] = keep[l[c]];
  }
  return out;
}

// Where a direction of a station's scanner frame falls on its grid.
class GridLookup {
 public:
  explicit GridLookup(const Scan& scan) : grid_(GridOf(scan)), rows_(scan.rows), cols_(scan.cols) {
    const std::vector<double>& az = grid_.azimuth_rad;
    const std::vector<double>& el = grid_.elevation_rad;
    azimuth_step_ = cols_ > 1 ? std::abs(az.back() - az.front()) / (cols_ - 1) : 1e-3;
    elevation_step_ = rows_ > 1 ? std::abs(el.front() - el.back()) / (rows_ - 1) : 1e-3;
  }

  // The nearest cell of the direction of `p` (scanner frame), or false when it lies outside the grid by
  // more than half a step.
  bool Cell(const Eigen::Vector3d& p, int* row, int* col) const {
    const double range = p.norm();
    if (range <= 0.0) return false;
    const std::vector<double>& az = grid_.azimuth_rad;
    const std::vector<double>& el = grid_.elevation_rad;
    // Azimuth relative to the first column, in [0, 2π): the grid may span past ±π.
    const double relative =
        std::fmod(WrapAngle(std::atan2(p.x(), p.y()) - az.front()) + 2.0 * M_PI, 2.0 * M_PI);
    const double azimuth = az.front() + relative;
    const auto c_it = std::lower_bound(az.begin(), az.end(), azimuth);
    int c = static_cast<int>(c_it - az.begin());
    if (c == cols_) {
      if (azimuth - az.back() > 0.5 * azimuth_step_) return false;
      c = cols_ - 1;
    } else if (c > 0 && azimuth - az[c - 1] < az[c] - azimuth) {
      --c;
    }
    const double elevation = std::asin(std::clamp(p.z() / range, -1.0, 1.0));
    if (elevation > el.front() + 0.5 * elevation_step_ || elevation < el.back() - 0.5 * elevation_step_)
      return false;
    // Elevations decrease down the rows.
    const auto r_it = std::lower_bound(el.begin(), el.end(), elevation, std::greater<double>());
    int r = static_cast<int>(r_it - el.begin());
    if (r == rows_) {
      r = rows_ - 1;
    } else if (r > 0 && el[r - 1] - elevation < elevation - el[r]) {
      --r;
    }
    *row = r;
    *col = c;
    return true;
  }

  double step_rad() const { return std::max(azimuth_step_, elevation_step_); }

 private:
  ScanGrid grid_;
  int rows_, cols_;
  double azimuth_step_ = 0, elevation_step_ = 0;
};

}  // namespace lidarshop
