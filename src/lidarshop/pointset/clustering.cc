#include "lidarshop/pointset/clustering.h"

#include <algorithm>
#include <numeric>
#include <random>

#include <fmt/format.h>

#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Union-find with the smaller index as root, so that roots do not depend on the order of unions.
struct DisjointSets {
  std::vector<uint32_t> parent;
  explicit DisjointSets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t Find(uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void Union(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a < b) parent[b] = a;
    if (b < a) parent[a] = b;
  }
};

}  // namespace

void EuclideanClusterOptions::Check() const { Validate(*this); }

void KMeansOptions::Check() const { Validate(*this); }

ClusterResult EuclideanClusters(const PointCloud& cloud, const EuclideanClusterOptions& options) {
  options.Check();
  CheckCloudHasPoints(cloud, 1, "Euclidean clustering");
  const PointKdTree tree(cloud.points);
  const float radius = static_cast<float>(options.radius_m);
  const int64_t n = static_cast<int64_t>(cloud.size());
  DisjointSets sets(cloud.size());
  // Blocks of points: neighbours found in parallel, edges joined serially (bounded memory, fixed order).
  constexpr int64_t kBlock = 1 << 16;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> edges((kBlock + 1023) / 1024);
  for (int64_t block = 0; block < n; block += kBlock) {
    const int64_t block_end = std::min(n, block + kBlock);
    const int64_t chunks = (block_end - block + 1023) / 1024;
    ParallelFor(chunks, [&](int64_t chunk) {
      auto& out = edges[chunk];
      out.clear();
      const int64_t begin = block + chunk * 1024, end = std::min(block_end, begin + 1024);
      for (int64_t i = begin; i < end; ++i) {
        tree.ForEachInRadius(cloud.points[i], radius, [&](uint32_t j, float) {
          if (j > i) out.emplace_back(static_cast<uint32_t>(i), j);
        });
      }
    });
    for (int64_t chunk = 0; chunk < chunks; ++chunk) {
      for (const auto& [a, b] : edges[chunk]) sets.Union(a, b);
    }
  }
  std::vector<int64_t> root_size(cloud.size(), 0);
  for (uint32_t i = 0; i < n; ++i) ++root_size[sets.Find(i)];
  std::vector<uint32_t> roots;
  for (uint32_t i = 0; i < n; ++i) {
    const int64_t size = root_size[i];
    if (size >= options.min_points && (options.max_points == 0 || size <= options.max_points))
      roots.push_back(i);
  }
  std::stable_sort(roots.begin(), roots.end(),
                   [&](uint32_t a, uint32_t b) { return root_size[a] > root_size[b]; });
  std::vector<int32_t> cluster_of_root(cloud.size(), kNoCluster);
  ClusterResult result;
  for (uint32_t root : roots) {
    cluster_of_root[root] = static_cast<int32_t>(result.sizes.size());
    result.sizes.push_back(root_size[root]);
  }
  result.labels.resize(cloud.size());
  for (uint32_t i = 0; i < n; ++i) result.labels[i] = cluster_of_root[sets.Find(i)];
  return result;
}

KMeansResult KMeans(const PointCloud& cloud, const KMeansOptions& options) {
  options.Check();
  CheckCloudHasPoints(cloud, 1, "k-means");
  if (options.clusters > static_cast<int64_t>(cloud.size())) {
    throw InputError(
        fmt::format("k-means: k = {} is larger than the cloud ({} points)", options.clusters, cloud.size()));
  }
  const int64_t n = static_cast<int64_t>(cloud.size());
  const int k = options.clusters;
  std::mt19937_64 random(options.seed);
  auto uniform = [&]() { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
  // k-means++: each next centre drawn with probability proportional to the
  // squared distance to the nearest one.
  KMeansResult result;
  std::vector<double> nearest_sq(cloud.size(), std::numeric_limits<double>::infinity());
  result.centers.push_back(cloud.points[random() % n].cast<double>());
  while (static_cast<int>(result.centers.size()) < k) {
    const Eigen::Vector3d& last = result.centers.back();
    ParallelFor(
        n,
        [&](int64_t i) {
          nearest_sq[i] = std::min(nearest_sq[i], (cloud.points[i].cast<double>() - last).squaredNorm());
        },
        4096);
    const double total = std::accumulate(nearest_sq.begin(), nearest_sq.end(), 0.0);
    int64_t chosen = random() % n;  // all points on the centres already: any point
    if (total > 0.0) {
      double target = uniform() * total;
      for (chosen = 0; chosen < n - 1; ++chosen) {
        target -= nearest_sq[chosen];
        if (target < 0.0) break;
      }
    }
    result.centers.push_back(cloud.points[chosen].cast<double>());
  }
  result.labels.assign(cloud.size(), 0);
  for (result.iterations = 1; result.iterations <= options.max_iterations; ++result.iterations) {
    ParallelFor(
        n,
        [&](int64_t i) {
          const Eigen::Vector3d p = cloud.points[i].cast<double>();
          double best = std::numeric_limits<double>::infinity();
          for (int c = 0; c < k; ++c) {
            const double d = (p - result.centers[c]).squaredNorm();
            if (d < best) {
              best = d;
              result.labels[i] = c;
            }
          }
        },
        4096);
    // Serial sums in point order: centres do not depend on the thread count.
    std::vector<Eigen::Vector3d> sums(k, Eigen::Vector3d::Zero());
    std::vector<int64_t> counts(k, 0);
    for (int64_t i = 0; i < n; ++i) {
      sums[result.labels[i]] += cloud.points[i].cast<double>();
      ++counts[result.labels[i]];
    }
    double moved = 0.0;
    for (int c = 0; c < k; ++c) {
      if (counts[c] == 0) continue;  // an empty cluster keeps its centre
      const Eigen::Vector3d center = sums[c] / static_cast<double>(counts[c]);
      moved = std::max(moved, (center - result.centers[c]).norm());
      result.centers[c] = center;
    }
    if (moved <= options.tolerance_m) break;
  }
  result.iterations = std::min(result.iterations, options.max_iterations);
  for (int64_t i = 0; i < n; ++i) {
    result.inertia_m2 += (cloud.points[i].cast<double>() - result.centers[result.labels[i]]).squaredNorm();
  }
  return result;
}

}  // namespace lidarshop
