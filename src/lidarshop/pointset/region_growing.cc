#include "lidarshop/pointset/region_growing.h"

#include <cmath>
#include <deque>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

bool Joined(const Scan& scan, cv::Point a, cv::Point b, double ratio) {
  if (!scan.valid.at<uint8_t>(b) || !scan.valid.at<uint8_t>(a)) return false;
  const float ra = scan.range.at<float>(a), rb = scan.range.at<float>(b);
  return std::abs(ra - rb) <= ratio * std::min(ra, rb);
}

// Breadth-first front from `seed` over cells whose `labels` are kNoLabel; marks
// them `label`. Returns the count.
int64_t Grow(const Scan& scan, cv::Point seed, const RegionGrowingOptions& options,
             const GrowCondition& condition, int32_t label, cv::Mat* labels, std::vector<cv::Point>* cells) {
  cells->clear();
  std::deque<cv::Point> front{seed};
  labels->at<int32_t>(seed) = label;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  while (!front.empty()) {
    const cv::Point from = front.front();
    front.pop_front();
    cells->push_back(from);
    for (const cv::Point& step : steps) {
      const cv::Point to = from + step;
      if (to.x < 0 || to.y < 0 || to.x >= scan.cols || to.y >= scan.rows) continue;
      if (labels->at<int32_t>(to) != kNoLabel || !Joined(scan, from, to, options.max_range_jump_ratio))
        continue;
      if (!condition(from, to)) continue;
      labels->at<int32_t>(to) = label;
      front.push_back(to);
    }
  }
  return static_cast<int64_t>(cells->size());
}

}  // namespace

void RegionGrowingOptions::Check() const { Validate(*this); }

GrowCondition NormalAngleCondition(const Scan& scan, double max_angle_deg) {
  CheckOption(max_angle_deg > 0.0, fmt::format("normal angle must be > 0 degrees, got {}", max_angle_deg));
  if (scan.normal.empty()) throw InputError("region growing by normal angle: the scan has no normals");
  const float min_cos = static_cast<float>(std::cos(max_angle_deg * M_PI / 180.0));
  return [normal = scan.normal, min_cos](cv::Point from, cv::Point to) {
    return normal.at<cv::Vec3f>(from).dot(normal.at<cv::Vec3f>(to)) >= min_cos;
  };
}

cv::Mat GrowRegion(const Scan& scan, cv::Point seed, const RegionGrowingOptions& options,
                   const GrowCondition& condition) {
  options.Check();
  if (seed.x < 0 || seed.y < 0 || seed.x >= scan.cols || seed.y >= scan.rows ||
      !scan.valid.at<uint8_t>(seed)) {
    throw InputError(fmt::format("region growing: seed (row {}, col {}) is outside the scan or has no return",
                                 seed.y, seed.x));
  }
  cv::Mat labels(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  std::vector<cv::Point> cells;
  Grow(scan, seed, options, condition, 0, &labels, &cells);
  cv::Mat region = labels == 0;
  return region;
}

cv::Mat SegmentByRegionGrowing(const Scan& scan, const RegionGrowingOptions& options,
                               const GrowCondition& condition, int* num_regions) {
  options.Check();
  cv::Mat labels(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  constexpr int32_t kTooSmall = -2;  // visited, but its region was dropped
  std::vector<cv::Point> cells;
  int32_t next = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col) || labels.at<int32_t>(row, col) != kNoLabel) continue;
      if (Grow(scan, {col, row}, options, condition, next, &labels, &cells) >= options.min_region_cells) {
        ++next;
      } else {
        for (const cv::Point& cell : cells) labels.at<int32_t>(cell) = kTooSmall;
      }
    }
  }
  labels.setTo(kNoLabel, labels == kTooSmall);
  if (num_regions) *num_regions = next;
  return labels;
}

}  // namespace lidarshop
