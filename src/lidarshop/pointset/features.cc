#include "lidarshop/pointset/features.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

constexpr int kBins = 11;

int Bin(double value, double low, double high) {
  return std::clamp(static_cast<int>(std::floor((value - low) / (high - low) * kBins)), 0, kBins - 1);
}

// Simplified point feature histogram of one point (its pairs with every neighbour), unnormalized.
void AddPair(const Eigen::Vector3f& ps, const Eigen::Vector3f& ns, const Eigen::Vector3f& pt,
             const Eigen::Vector3f& nt, std::array<float, 33>* histogram) {
  Eigen::Vector3d d = (pt - ps).cast<double>();
  const double length = d.norm();
  if (length == 0.0) return;
  d /= length;
  const Eigen::Vector3d u = ns.cast<double>();
  const Eigen::Vector3d v = u.cross(d);
  if (v.norm() < 1e-12) return;
  const Eigen::Vector3d vn = v.normalized(), w = u.cross(vn);
  const Eigen::Vector3d n = nt.cast<double>();
  (*histogram)[Bin(vn.dot(n), -1.0, 1.0)] += 1.0f;
  (*histogram)[kBins + Bin(u.dot(d), -1.0, 1.0)] += 1.0f;
  (*histogram)[2 * kBins + Bin(std::atan2(w.dot(n), u.dot(n)), -M_PI, M_PI)] += 1.0f;
}

void Normalize(Fpfh* feature) {
  for (int h = 0; h < 3; ++h) {
    float sum = 0.0f;
    for (int b = 0; b < kBins; ++b) sum += (*feature)[h * kBins + b];
    if (sum > 0.0f) {
      for (int b = 0; b < kBins; ++b) (*feature)[h * kBins + b] *= 100.0f / sum;
    }
  }
}

float FeatureDistanceSq(const Fpfh& a, const Fpfh& b) {
  float sum = 0.0f;
  for (int i = 0; i < 33; ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return sum;
}

// For every feature of `from`, the index of the nearest feature of `to` (brute force, parallel).
std::vector<uint32_t> NearestFeatures(const std::vector<Fpfh>& from, const std::vector<Fpfh>& to) {
  std::vector<uint32_t> nearest(from.size());
  ParallelFor(
      static_cast<int64_t>(from.size()),
      [&](int64_t i) {
        float best = std::numeric_limits<float>::infinity();
        for (uint32_t j = 0; j < to.size(); ++j) {
          const float d = FeatureDistanceSq(from[i], to[j]);
          if (d < best) {
            best = d;
            nearest[i] = j;
          }
        }
      },
      16);
  return nearest;
}

PointCloud Prepare(const PointCloud& cloud, const GlobalAlignOptions& options, std::string_view what) {
  CheckCloudHasShape(cloud, what);
  PointCloud small = VoxelDownsample(cloud, options.voxel_m);
  CheckCloudHasPoints(small, 10, fmt::format("{} after {} m voxels", what, options.voxel_m));
  if (small.normals.size() == small.size()) return small;  // averaged from the cloud's own (oriented) normals
  NormalOptions normal_options;
  normal_options.radius_m = options.normal_radius_m;
  small.normals = EstimateNormals(small, normal_options).normals;
  return small;
}

}  // namespace

void GlobalAlignOptions::Check() const { Validate(*this); }

std::vector<Fpfh> ComputeFpfh(const PointCloud& cloud, double radius_m) {
  CheckOption(radius_m > 0.0, fmt::format("FPFH radius must be > 0 m, got {}", radius_m));
  if (cloud.normals.size() != cloud.size()) throw InputError("FPFH: the cloud has no normals");
  const PointKdTree tree(cloud.points);
  const float radius = static_cast<float>(radius_m);
  const int64_t n = static_cast<int64_t>(cloud.size());
  std::vector<Fpfh> spfh(n, Fpfh{});
  ParallelFor(
      n,
      [&](int64_t i) {
        tree.ForEachInRadius(cloud.points[i], radius, [&](uint32_t j, float) {
          if (j != i) AddPair(cloud.points[i], cloud.normals[i], cloud.points[j], cloud.normals[j], &spfh[i]);
        });
        Normalize(&spfh[i]);
      },
      256);
  std::vector<Fpfh> fpfh(n, Fpfh{});
  ParallelFor(
      n,
      [&](int64_t i) {
        Fpfh& f = fpfh[i];
        f = spfh[i];
        std::vector<std::pair<uint32_t, float>> matches;
        tree.RadiusSearch(cloud.points[i], radius, &matches, true);  // sorted: sums in a fixed order
        for (const auto& [j, distance_sq] : matches) {
          if (j == i || distance_sq == 0.0f) continue;
          const float weight = 1.0f / (std::sqrt(distance_sq) * static_cast<float>(matches.size() - 1));
          for (int b = 0; b < 33; ++b) f[b] += weight * spfh[j][b];
        }
        Normalize(&f);
      },
      256);
  return fpfh;
}

GlobalAlignResult AlignGlobally(const PointCloud& fixed, const PointCloud& moving,
                                const GlobalAlignOptions& options) {
  options.Check();
  const PointCloud a = Prepare(fixed, options, "global alignment (fixed cloud)");
  const PointCloud b = Prepare(moving, options, "global alignment (moving cloud)");
  const std::vector<Fpfh> fa = ComputeFpfh(a, options.feature_radius_m),
                          fb = ComputeFpfh(b, options.feature_radius_m);
  // Mutual nearest neighbours in feature space.
  const std::vector<uint32_t> b_to_a = NearestFeatures(fb, fa), a_to_b = NearestFeatures(fa, fb);
  std::vector<std::pair<uint32_t, uint32_t>> matches;  // (moving, fixed)
  for (uint32_t i = 0; i < b_to_a.size(); ++i) {
    if (a_to_b[b_to_a[i]] == i) matches.emplace_back(i, b_to_a[i]);
  }
  GlobalAlignResult result;
  result.matches = static_cast<int64_t>(matches.size());
  if (matches.size() < 3)
    throw InputError(fmt::format("global alignment: only {} feature matches", matches.size()));
  std::mt19937_64 random(options.seed);
  const double inlier_sq = options.inlier_distance_m * options.inlier_distance_m;
  auto count_inliers = [&](const Eigen::Matrix4d& t) {
    int64_t inliers = 0;
    for (const auto& [m, f] : matches) {
      inliers += (t.topLeftCorner<3, 3>() * b.points[m].cast<double>() + t.topRightCorner<3, 1>() -
                  a.points[f].cast<double>())
                     .squaredNorm() < inlier_sq;
    }
    return inliers;
  };
  constexpr int kBatch = 64;
  Eigen::Matrix4d best = Eigen::Matrix4d::Identity();
  int64_t best_inliers = -1;
  for (result.iterations = 0; result.iterations < options.max_iterations;) {
    const int count = std::min(kBatch, options.max_iterations - result.iterations);
    std::array<Eigen::Matrix4d, kBatch> poses;
    std::array<int64_t, kBatch> scores;
    scores.fill(-1);
    for (int h = 0; h < count; ++h) {
      Eigen::Matrix3d from, to;
      for (int k = 0; k < 3; ++k) {
        const auto& [m, f] = matches[random() % matches.size()];
        from.col(k) = b.points[m].cast<double>();
        to.col(k) = a.points[f].cast<double>();
      }
      bool similar = true;  // a rigid motion keeps the triangle's edge lengths
      for (int k = 0; k < 3; ++k) {
        const double lf = (from.col(k) - from.col((k + 1) % 3)).norm(),
                     lt = (to.col(k) - to.col((k + 1) % 3)).norm();
        similar =
            similar && std::min(lf, lt) >= options.edge_ratio * std::max(lf, lt) && lf > options.voxel_m;
      }
      if (!similar) continue;
      poses[h] = Eigen::umeyama(from, to, false);
      scores[h] = 0;
    }
    ParallelFor(count, [&](int64_t h) {
      if (scores[h] == 0) scores[h] = count_inliers(poses[h]);
    });
    for (int h = 0; h < count; ++h) {
      if (scores[h] > best_inliers) {
        best_inliers = scores[h];
        best = poses[h];
      }
    }
    result.iterations += count;
  }
  if (best_inliers < 3) throw InputError("global alignment: no triple of feature matches agrees on a pose");
  // Refit to all agreeing matches.
  Eigen::Matrix3Xd from(3, best_inliers), to(3, best_inliers);
  int64_t k = 0;
  for (const auto& [m, f] : matches) {
    const Eigen::Vector3d p =
        best.topLeftCorner<3, 3>() * b.points[m].cast<double>() + best.topRightCorner<3, 1>();
    if ((p - a.points[f].cast<double>()).squaredNorm() >= inlier_sq) continue;
    from.col(k) = b.points[m].cast<double>();
    to.col(k++) = a.points[f].cast<double>();
  }
  result.fixed_from_moving = Eigen::umeyama(from, to, false);
  result.inliers = count_inliers(result.fixed_from_moving);
  return result;
}

}  // namespace lidarshop
