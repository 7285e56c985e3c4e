#include "lidarshop/pointset/hough_planes.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/pointset/filters.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void HoughPlaneOptions::Check() const { Validate(*this); }

std::vector<PlaneFit> DetectPlanesHough(const PointCloud& cloud, const HoughPlaneOptions& options) {
  options.Check();
  CheckCloudHasShape(cloud, "Hough planes");
  // The ball accumulator's normal directions (upper hemisphere; a plane and its flip are one plane).
  std::vector<Eigen::Vector3d> directions;
  const double step = options.angle_step_deg * M_PI / 180.0;
  for (double elevation = 0.0; elevation <= M_PI / 2 + 1e-9; elevation += step) {
    const int cells = std::max(1, static_cast<int>(std::round(2.0 * M_PI * std::cos(elevation) / step)));
    for (int a = 0; a < cells; ++a) {
      const double azimuth = 2.0 * M_PI * a / cells;
      // Half the ring at elevation 0 duplicates the other half (n and -n); keep azimuth in [0, π) there.
      if (elevation == 0.0 && azimuth >= M_PI - 1e-9) continue;
      directions.emplace_back(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    }
  }
  const Eigen::AlignedBox3f bounds = Bounds(cloud);
  const Eigen::Vector3d centre =
      bounds.center().cast<double>();  // offsets relative to the centre: fewer cells
  const double reach = 0.5 * bounds.diagonal().cast<double>().norm();
  const int distance_cells = 2 * static_cast<int>(std::ceil(reach / options.distance_step_m)) + 1;
  const double half_cell = 0.5 * options.distance_step_m;

  std::vector<uint8_t> remaining(cloud.size(), 1);
  std::vector<PlaneFit> planes;
  while (static_cast<int>(planes.size()) < options.max_planes) {
    PointCloud left;
    std::vector<uint32_t> left_index;
    for (uint32_t i = 0; i < cloud.size(); ++i) {
      if (remaining[i]) {
        left.points.push_back(cloud.points[i]);
        left_index.push_back(i);
      }
    }
    if (static_cast<int64_t>(left.size()) < options.min_inliers) break;
    const std::vector<uint8_t> voter_flags =
        RandomSampleInliers(left, options.max_voters, options.seed + planes.size());
    std::vector<Eigen::Vector3d> voters;
    for (size_t i = 0; i < left.size(); ++i) {
      if (voter_flags[i]) voters.push_back(left.points[i].cast<double>() - centre);
    }
    // Each direction owns its row of cells: parallel and deterministic.
    std::vector<int64_t> best_votes(directions.size(), 0);
    std::vector<int> best_cell(directions.size(), 0);
    ParallelFor(static_cast<int64_t>(directions.size()), [&](int64_t d) {
      std::vector<int32_t> votes(distance_cells, 0);
      for (const Eigen::Vector3d& p : voters) {
        const int cell = static_cast<int>(std::floor(directions[d].dot(p) / options.distance_step_m + 0.5)) +
                         distance_cells / 2;
        if (cell >= 0 && cell < distance_cells) ++votes[cell];
      }
      const auto top = std::max_element(votes.begin(), votes.end());
      best_votes[d] = *top;
      best_cell[d] = static_cast<int>(top - votes.begin());
    });
    const size_t d = std::max_element(best_votes.begin(), best_votes.end()) - best_votes.begin();
    PlaneFit fit;
    fit.normal = directions[d];
    fit.offset_m = -((best_cell[d] - distance_cells / 2) * options.distance_step_m + fit.normal.dot(centre));
    fit.iterations = static_cast<int>(best_votes[d]);
    // The cell's plane is only as good as the accumulator's resolution: collect its points and refit by least
    // squares, a few rounds (each round's plane collects the next round's points).
    for (int round = 0; round < 3; ++round) {
      std::vector<uint32_t> inliers;
      for (uint32_t i : left_index) {
        if (std::abs(fit.Distance(cloud.points[i])) <= half_cell) inliers.push_back(i);
      }
      if (static_cast<int64_t>(inliers.size()) < 3 || inliers == fit.inliers) break;
      fit.inliers = std::move(inliers);
      RefitPlane(cloud.points, &fit);
    }
    if (static_cast<int64_t>(fit.inliers.size()) < options.min_inliers) break;
    for (uint32_t i : fit.inliers) remaining[i] = 0;
    planes.push_back(std::move(fit));
  }
  return planes;
}

}  // namespace lidarshop
