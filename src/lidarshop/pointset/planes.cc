#include "lidarshop/pointset/planes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <random>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "lidarshop/pointset/filters.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

constexpr int kBatch = 32;  // hypotheses scored together

struct Hypothesis {
  Eigen::Vector3d normal;
  double offset = 0.0;
  int64_t inliers = -1;  // -1 = degenerate sample
};

PlaneFit FitAmong(const std::vector<Eigen::Vector3f>& points, const std::vector<uint32_t>& candidates,
                  const RansacPlaneOptions& options, std::mt19937_64* random) {
  const int64_t n = static_cast<int64_t>(candidates.size());
  const double threshold = options.distance_threshold_m;
  Hypothesis best;
  int iterations = 0;
  int64_t needed = options.max_iterations;
  while (iterations < std::min<int64_t>(needed, options.max_iterations)) {
    std::array<Hypothesis, kBatch> batch;
    const int count = static_cast<int>(std::min<int64_t>(kBatch, options.max_iterations - iterations));
    for (int h = 0; h < count; ++h) {
      const Eigen::Vector3d a = points[candidates[(*random)() % n]].cast<double>();
      const Eigen::Vector3d b = points[candidates[(*random)() % n]].cast<double>();
      const Eigen::Vector3d c = points[candidates[(*random)() % n]].cast<double>();
      const Eigen::Vector3d cross = (b - a).cross(c - a);
      if (cross.norm() < 1e-12) continue;
      batch[h].normal = cross.normalized();
      batch[h].offset = -batch[h].normal.dot(a);
      batch[h].inliers = 0;
    }
    ParallelFor(count, [&](int64_t h) {
      if (batch[h].inliers < 0) return;
      int64_t inliers = 0;
      for (uint32_t i : candidates) {
        inliers += std::abs(batch[h].normal.dot(points[i].cast<double>()) + batch[h].offset) <= threshold;
      }
      batch[h].inliers = inliers;
    });
    for (int h = 0; h < count; ++h) {
      if (batch[h].inliers > best.inliers) best = batch[h];
    }
    iterations += count;
    // Adaptive stop: enough samples to draw an all-inlier triple with the asked confidence.
    const double ratio = static_cast<double>(std::max<int64_t>(best.inliers, 0)) / n;
    const double all_inliers = ratio * ratio * ratio;
    if (all_inliers >= 1.0 - 1e-12) break;
    if (all_inliers > 0.0) {
      needed =
          static_cast<int64_t>(std::ceil(std::log(1.0 - options.confidence) / std::log(1.0 - all_inliers)));
    }
  }
  PlaneFit fit;
  fit.iterations = iterations;
  if (best.inliers < 3) return fit;
  fit.normal = best.normal;
  fit.offset_m = best.offset;
  for (uint32_t i : candidates) {
    if (std::abs(fit.Distance(points[i])) <= threshold) fit.inliers.push_back(i);
  }
  RefitPlane(points, &fit);
  // The refitted plane's own inliers (usually a few more than the hypothesis's).
  std::vector<uint32_t> refined;
  for (uint32_t i : candidates) {
    if (std::abs(fit.Distance(points[i])) <= threshold) refined.push_back(i);
  }
  if (refined.size() >= fit.inliers.size()) {
    fit.inliers = std::move(refined);
    RefitPlane(points, &fit);
  }
  return fit;
}

}  // namespace

void RefitPlane(const std::vector<Eigen::Vector3f>& points, PlaneFit* fit) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (uint32_t i : fit->inliers) mean += points[i].cast<double>();
  mean /= static_cast<double>(fit->inliers.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (uint32_t i : fit->inliers) {
    const Eigen::Vector3d d = points[i].cast<double>() - mean;
    covariance += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d normal = solver.eigenvectors().col(0).normalized();
  if (normal.dot(fit->normal) < 0.0) normal = -normal;  // keep the hypothesis's side
  fit->normal = normal;
  fit->offset_m = -normal.dot(mean);
  fit->rms_m = std::sqrt(std::max(0.0, solver.eigenvalues()[0]) / static_cast<double>(fit->inliers.size()));
}

void RansacPlaneOptions::Check() const { Validate(*this); }

PlaneFit FitPlaneRansac(const PointCloud& cloud, const RansacPlaneOptions& options) {
  RansacPlaneOptions best_only = options;
  best_only.max_planes = 1;
  best_only.min_inliers = 3;
  std::vector<PlaneFit> planes = DetectPlanesRansac(cloud, best_only);
  if (planes.empty()) throw InputError("RANSAC plane: every sample was degenerate (collinear points)");
  return std::move(planes.front());
}

std::vector<PlaneFit> DetectPlanesRansac(const PointCloud& cloud, const RansacPlaneOptions& options) {
  options.Check();
  CheckCloudHasShape(cloud, "RANSAC planes");
  CheckCloudHasPoints(cloud, 3, "RANSAC planes");
  std::vector<uint32_t> remaining(cloud.size());
  for (uint32_t i = 0; i < remaining.size(); ++i) remaining[i] = i;
  std::mt19937_64 random(options.seed);
  std::vector<PlaneFit> planes;
  while (static_cast<int>(planes.size()) < options.max_planes &&
         static_cast<int64_t>(remaining.size()) >= options.min_inliers) {
    PlaneFit fit = FitAmong(cloud.points, remaining, options, &random);
    if (static_cast<int64_t>(fit.inliers.size()) < options.min_inliers) break;
    std::vector<uint32_t> rest;
    std::set_difference(remaining.begin(), remaining.end(), fit.inliers.begin(), fit.inliers.end(),
                        std::back_inserter(rest));
    remaining = std::move(rest);
    planes.push_back(std::move(fit));
  }
  return planes;
}

}  // namespace lidarshop
