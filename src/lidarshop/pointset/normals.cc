#include "lidarshop/pointset/normals.h"

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Accumulates neighbours relative to the query point (keeps precision far from the origin).
struct Covariance {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
  int count = 0;
  void Add(const Eigen::Vector3f& relative) {
    const Eigen::Vector3d p = relative.cast<double>();
    sum += p;
    sum_outer += p * p.transpose();
    ++count;
  }
  // Normal toward `to_viewpoint` and curvature; false when fewer than 3 neighbours or no spread.
  bool Solve(const Eigen::Vector3f& to_viewpoint, Eigen::Vector3f* normal, float* curvature) const {
    if (count < 3) return false;
    const Eigen::Vector3d mean = sum / count;
    const Eigen::Matrix3d covariance = sum_outer / count - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    const Eigen::Vector3d lambda = solver.eigenvalues().cwiseMax(0.0);
    if (lambda.sum() <= 0.0) return false;
    Eigen::Vector3f n = solver.eigenvectors().col(0).normalized().cast<float>();
    if (n.dot(to_viewpoint) < 0.0f) n = -n;
    *normal = n;
    *curvature = static_cast<float>(lambda[0] / lambda.sum());
    return true;
  }
};

}  // namespace

void NormalOptions::Check() const { Validate(*this); }

NormalResult EstimateNormals(const PointCloud& cloud, const NormalOptions& options) {
  options.Check();
  CheckCloudHasShape(cloud, "normal estimation");
  if (options.radius_m == 0.0) CheckCloudHasPoints(cloud, options.neighbors, "normal estimation (k nearest)");
  const PointKdTree tree(cloud.points);
  NormalResult result;
  result.normals.assign(cloud.size(), Eigen::Vector3f::Zero());
  result.curvature.assign(cloud.size(), 1.0f / 3.0f);
  const float radius = static_cast<float>(options.radius_m);
  ParallelForRange(
      static_cast<int64_t>(cloud.size()),
      [&](int64_t begin, int64_t end) {
        std::vector<uint32_t> indices;
        std::vector<float> distances_sq;
        std::vector<std::pair<uint32_t, float>> matches;
        for (int64_t i = begin; i < end; ++i) {
          const Eigen::Vector3f& p = cloud.points[i];
          Covariance covariance;
          if (radius > 0.0f && options.max_neighbors == 0) {
            tree.ForEachInRadius(p, radius, [&](uint32_t j, float) { covariance.Add(cloud.points[j] - p); });
          } else {
            tree.KNearest(p, radius > 0.0f ? options.max_neighbors : options.neighbors, &indices,
                          &distances_sq);
            for (size_t n = 0; n < indices.size(); ++n) {
              if (radius > 0.0f && distances_sq[n] >= radius * radius) break;
              covariance.Add(cloud.points[indices[n]] - p);
            }
          }
          covariance.Solve(options.viewpoint - p, &result.normals[i], &result.curvature[i]);
        }
      },
      512);
  return result;
}

bool GridNormalAt(const Scan& scan, const NormalOptions& options, int row, int col, cv::Vec3f* normal,
                  float* curvature) {
  if (!scan.valid.at<uint8_t>(row, col)) return false;
  const int w = options.window_cells;
  const float radius_sq = static_cast<float>(options.radius_m * options.radius_m);
  const cv::Vec3f& c = scan.point.at<cv::Vec3f>(row, col);
  const Eigen::Vector3f centre(c[0], c[1], c[2]);
  Covariance covariance;
  for (int r = std::max(0, row - w); r <= std::min(scan.rows - 1, row + w); ++r) {
    for (int k = std::max(0, col - w); k <= std::min(scan.cols - 1, col + w); ++k) {
      if (!scan.valid.at<uint8_t>(r, k)) continue;
      const cv::Vec3f& q = scan.point.at<cv::Vec3f>(r, k);
      const Eigen::Vector3f relative = Eigen::Vector3f(q[0], q[1], q[2]) - centre;
      if (radius_sq > 0.0f && relative.squaredNorm() >= radius_sq) continue;
      covariance.Add(relative);
    }
  }
  Eigen::Vector3f n;
  if (!covariance.Solve(-centre, &n, curvature)) return false;
  *normal = cv::Vec3f(n.x(), n.y(), n.z());
  return true;
}

GridNormalResult EstimateGridNormals(const Scan& scan, const NormalOptions& options) {
  options.Check();
  if (scan.CountValid() < 3) throw InputError("grid normals: the scan has fewer than 3 returns");
  GridNormalResult result{cv::Mat(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0)),
                          cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(NAN))};
  ParallelFor(scan.rows, [&](int64_t row) {
    for (int col = 0; col < scan.cols; ++col) {
      GridNormalAt(scan, options, static_cast<int>(row), col, &result.normal.at<cv::Vec3f>(row, col),
                   &result.curvature.at<float>(row, col));
    }
  });
  return result;
}

Scan WithGridNormals(const Scan& scan, const NormalOptions& options) {
  GridNormalResult result = EstimateGridNormals(scan, options);
  Scan out = scan;
  out.normal = result.normal;
  out.curvature = result.curvature;
  return out;
}

}  // namespace lidarshop
