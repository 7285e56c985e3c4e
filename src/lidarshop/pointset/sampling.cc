#include "lidarshop/pointset/sampling.h"

#include <algorithm>
#include <random>

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// [0, 1) from the top 53 bits: identical on every platform, unlike std::uniform_real_distribution.
double Uniform01(std::mt19937_64& random) { return static_cast<double>(random() >> 11) * 0x1.0p-53; }

}  // namespace

SurfaceSamples SampleSurface(const TriangleMesh& mesh, int64_t count, uint64_t seed) {
  SurfaceSamples samples;
  if (mesh.empty() || count <= 0) return samples;
  CheckMemoryBudget(SaturatingBytes(count, kSurfaceSampleBytes), fmt::format("sampling {} points", count));
  std::vector<double> cumulative_area(mesh.triangles.size());
  double total = 0.0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Eigen::Vector3d a = mesh.vertices[mesh.triangles[f][0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[mesh.triangles[f][1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[mesh.triangles[f][2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative_area[f] = total;
  }
  if (!(total > 0.0)) return samples;
  std::mt19937_64 random(seed);
  samples.points.reserve(count);
  samples.normals.reserve(count);
  samples.triangle_ids.reserve(count);
  for (int64_t s = 0; s < count; ++s) {
    const double pick = Uniform01(random) * total;
    size_t f =
        std::upper_bound(cumulative_area.begin(), cumulative_area.end(), pick) - cumulative_area.begin();
    f = std::min(f, cumulative_area.size() - 1);
    // Skip zero-area triangles that upper_bound can land on only at their exact boundary.
    while (f > 0 && cumulative_area[f] == cumulative_area[f - 1]) --f;
    double r1 = std::sqrt(Uniform01(random));
    double r2 = Uniform01(random);
    const Eigen::Vector3f& a = mesh.vertices[mesh.triangles[f][0]];
    const Eigen::Vector3f& b = mesh.vertices[mesh.triangles[f][1]];
    const Eigen::Vector3f& c = mesh.vertices[mesh.triangles[f][2]];
    const float wa = static_cast<float>(1.0 - r1);
    const float wb = static_cast<float>(r1 * (1.0 - r2));
    const float wc = static_cast<float>(r1 * r2);
    samples.points.push_back(wa * a + wb * b + wc * c);
    samples.normals.push_back((b - a).cross(c - a).normalized());
    samples.triangle_ids.push_back(static_cast<int32_t>(f));
  }
  return samples;
}

std::vector<float> SurfaceVariation(const PointKdTree& tree, float radius) {
  const auto points = tree.points();
  std::vector<float> variation(points.size(), 1.0f / 3.0f);
  ParallelForRange(
      static_cast<int64_t>(points.size()),
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          Eigen::Vector3d sum = Eigen::Vector3d::Zero();
          Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
          int n = 0;
          tree.ForEachInRadius(points[i], radius, [&](uint32_t j, float) {
            const Eigen::Vector3d p = (points[j] - points[i]).cast<double>();
            sum += p;
            sum_outer += p * p.transpose();
            ++n;
          });
          if (n < 3) continue;
          const Eigen::Vector3d mean = sum / n;
          const Eigen::Matrix3d covariance = sum_outer / n - mean * mean.transpose();
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance, Eigen::EigenvaluesOnly);
          const Eigen::Vector3d lambda = solver.eigenvalues().cwiseMax(0.0);
          const double trace = lambda.sum();
          variation[i] = trace > 0.0 ? static_cast<float>(lambda[0] / trace) : 0.0f;
        }
      },
      256);
  return variation;
}

}  // namespace lidarshop
