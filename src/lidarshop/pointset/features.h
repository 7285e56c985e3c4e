// Global initial alignment when there is no pose guess: FPFH features (Rusu et al. 2009, "Fast Point Feature
// Histograms for 3D registration"; PCL's FPFHEstimation, Open3D's compute_fpfh_feature) matched between two
// clouds, and RANSAC over triples of matches (Open3D's registration_ransac_based_on_feature_matching). The
// result is a rough fixed_from_moving to start IcpPointToPlane (registration.h) from.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

using Fpfh = std::array<float, 33>;  // 3 angle histograms of 11 bins, each summing to 100

// FPFH of every point from its neighbours within `radius_m` (metres, > 0). The cloud needs normals. Points
// with no neighbour get an all-zero feature.
std::vector<Fpfh> ComputeFpfh(const PointCloud& cloud, double radius_m);

struct GlobalAlignOptions {
  double voxel_m = 0.1;             // both clouds are voxel-subsampled first, metres, > 0
  double normal_radius_m = 0.25;    // normals of the subsampled clouds when they have none, metres
  double feature_radius_m = 0.5;    // FPFH radius, metres (> normal_radius_m typically)
  double inlier_distance_m = 0.15;  // a match agrees with a pose when closer than this after it, metres, > 0
  int max_iterations = 20000;       // RANSAC triples, >= 1
  double edge_ratio = 0.9;  // triples whose edge lengths differ more than this ratio are skipped, (0, 1]
  uint64_t seed = 1;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<GlobalAlignOptions>();

struct GlobalAlignResult {
  Eigen::Matrix4d fixed_from_moving = Eigen::Matrix4d::Identity();
  int64_t matches = 0;  // feature matches (mutual nearest neighbours)
  int64_t inliers = 0;  // matches that agree with the pose
  int iterations = 0;
};

// Both clouds in their own frames. FPFH needs consistently oriented normals: the clouds' own normals are used
// when present (scans: the `normal` channel, e.g. from EstimateGridNormals), else PCA normals toward each
// cloud's origin (right for clouds in their scanner's frame). Throws InputError on empty/degenerate clouds or
// when no triple agrees.
GlobalAlignResult AlignGlobally(const PointCloud& fixed, const PointCloud& moving,
                                const GlobalAlignOptions& options);

}  // namespace lidarshop
