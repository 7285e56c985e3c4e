#include "lidarshop/pointset/ground.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "lidarshop/pointset/planes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

constexpr size_t kMaxPoints = 50000;
constexpr double kInlierShareOfRange = 0.01;
constexpr double kMinShare = 0.15;
constexpr double kMaxTiltDeg = 60.0;
constexpr int kPlanes = 3;

}  // namespace

std::optional<GroundPlane> FindGround(const Scan& scan, const cv::Mat& exclude) {
  CheckScan(scan);
  LIDARSHOP_CHECK(exclude.empty() ||
                  (exclude.size() == cv::Size(scan.cols, scan.rows) && exclude.type() == CV_8U));
  std::vector<cv::Point> cells;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (scan.valid.at<uint8_t>(row, col) && (exclude.empty() || !exclude.at<uint8_t>(row, col))) {
        cells.emplace_back(col, row);
      }
    }
  }
  if (cells.size() < 100) return std::nullopt;
  const size_t stride = (cells.size() + kMaxPoints - 1) / kMaxPoints;
  PointCloud cloud;  // scanner frame
  std::vector<float> ranges;
  for (size_t i = 0; i < cells.size(); i += stride) {
    const cv::Vec3f p = scan.point.at<cv::Vec3f>(cells[i]);
    cloud.points.emplace_back(p[0], p[1], p[2]);
    ranges.push_back(scan.range.at<float>(cells[i]));
  }
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  const double median_range = ranges[ranges.size() / 2];
  if (!(median_range > 0)) return std::nullopt;
  RansacPlaneOptions options;
  options.distance_threshold_m = kInlierShareOfRange * median_range;
  options.max_planes = kPlanes;
  options.min_inliers = static_cast<int>(kMinShare * cloud.size());
  const std::vector<PlaneFit> planes = DetectPlanesRansac(cloud, options);
  const Eigen::Vector3d up_in_scanner = Eigen::Vector3d::UnitZ();
  std::optional<GroundPlane> ground;
  size_t best_inliers = 0;
  for (const PlaneFit& plane : planes) {
    if (plane.inliers.size() < kMinShare * cloud.size() || plane.inliers.size() <= best_inliers) continue;
    // Orient the normal towards the sensor (the origin): normal · 0 + offset > 0.
    Eigen::Vector3d normal = plane.normal;
    double offset = plane.offset_m;
    if (offset < 0) {
      normal = -normal;
      offset = -offset;
    }
    const double tilt_deg = std::acos(std::clamp(normal.dot(up_in_scanner), -1.0, 1.0)) * 180.0 / M_PI;
    if (tilt_deg > kMaxTiltDeg) continue;  // a wall, or a ceiling (its normal points down to the sensor)
    best_inliers = plane.inliers.size();
    ground = GroundPlane{(scan.world_from_scanner.topLeftCorner<3, 3>() * normal).normalized(),
                         static_cast<double>(plane.inliers.size()) / cloud.size(), tilt_deg};
  }
  return ground;
}

}  // namespace lidarshop
