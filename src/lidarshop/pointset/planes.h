// RANSAC plane fitting (Fischler and Bolles 1981; PCL's SACSegmentation, Open3D's segment_plane): planes
// through three random points, scored by their inliers within a distance; the best one is refitted to its
// inliers by least squares. Sequential detection takes the best plane, removes its inliers and repeats.
//
// Determinism: hypotheses are drawn serially from one seeded generator in batches and scored in parallel; the
// best is the one with most inliers, the earliest on ties, so the answer does not depend on the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct RansacPlaneOptions {
  double distance_threshold_m = 0.01;  // inlier distance to the plane, metres, > 0
  int max_iterations = 1000;           // hypotheses at most, >= 1
  double confidence = 0.999;           // stop early when a better plane is this unlikely to exist, (0, 1)
  int min_inliers = 3;                 // sequential detection stops below this many inliers, >= 3
  int max_planes = 1;                  // sequential detection: planes at most, >= 1
  uint64_t seed = 1;                   // every random choice
  void Check() const;                  // throws OptionsError
};
template <>
const StructInfo& InfoOf<RansacPlaneOptions>();

struct PlaneFit {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit normal
  double offset_m = 0.0;                              // plane: normal · x + offset_m = 0
  std::vector<uint32_t> inliers;                      // indices into the cloud given, increasing
  double rms_m = 0.0;                                 // RMS distance of the inliers to the refitted plane
  int iterations = 0;                                 // hypotheses scored
  double Distance(const Eigen::Vector3f& point) const { return normal.dot(point.cast<double>()) + offset_m; }
};

// Least-squares plane through points[fit->inliers] (normal = smallest eigenvector of their covariance, on the
// side of the current fit->normal); sets normal, offset_m and rms_m.
void RefitPlane(const std::vector<Eigen::Vector3f>& points, PlaneFit* fit);

// The plane with most inliers. Throws InputError on fewer than 3 points or identical points.
PlaneFit FitPlaneRansac(const PointCloud& cloud, const RansacPlaneOptions& options);

// Up to options.max_planes planes, each from the points the earlier ones left (indices into `cloud`).
std::vector<PlaneFit> DetectPlanesRansac(const PointCloud& cloud, const RansacPlaneOptions& options);

}  // namespace lidarshop
