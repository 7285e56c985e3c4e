// Grouping points: Euclidean clustering (PCL's EuclideanClusterExtraction), which is the radially bounded
// nearest-neighbour clustering (RBNN, Klasing et al. 2008: points closer than a radius share a cluster, taken
// transitively), and k-means with k-means++ seeding (Arthur and Vassilvitskii 2007).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

constexpr int32_t kNoCluster = -1;

struct EuclideanClusterOptions {
  double radius_m = 0.05;  // points closer than this are neighbours, metres, > 0
  int64_t min_points = 1;  // smaller clusters become noise (kNoCluster), >= 1
  int64_t max_points = 0;  // larger clusters become noise too (0 = no limit)
  void Check() const;      // throws OptionsError
};
template <>
const StructInfo& InfoOf<EuclideanClusterOptions>();

struct ClusterResult {
  std::vector<int32_t> labels;  // #P cluster of each point, kNoCluster for noise
  // Points per cluster; clusters numbered by size, largest first (ties: the one with the lowest point index).
  std::vector<int64_t> sizes;
  int num_clusters() const { return static_cast<int>(sizes.size()); }
};

// Connected components of the "closer than radius_m" graph. Same answer whatever the thread count.
ClusterResult EuclideanClusters(const PointCloud& cloud, const EuclideanClusterOptions& options);

struct KMeansOptions {
  int clusters = 8;           // k, >= 1 and <= #P
  int max_iterations = 100;   // Lloyd iterations at most, >= 1
  double tolerance_m = 1e-6;  // stop when no centre moves more than this, metres, >= 0
  uint64_t seed = 1;          // k-means++ seeding
  void Check() const;         // throws OptionsError
};
template <>
const StructInfo& InfoOf<KMeansOptions>();

struct KMeansResult {
  std::vector<int32_t> labels;           // #P index of the nearest centre
  std::vector<Eigen::Vector3d> centers;  // k centres
  double inertia_m2 = 0.0;               // sum of squared distances to the assigned centres
  int iterations = 0;
};

// Throws InputError when k exceeds the number of points or the cloud is empty.
KMeansResult KMeans(const PointCloud& cloud, const KMeansOptions& options);

}  // namespace lidarshop
