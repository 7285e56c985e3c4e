#include "lidarshop/geometry/transform.h"

#include <cmath>

#include <fmt/format.h>

namespace lidarshop {

Eigen::Matrix3d RotationFromEulerDegrees(const Eigen::Vector3d& rotate_deg) {
  const Eigen::Vector3d radians = rotate_deg * (M_PI / 180.0);
  return (Eigen::AngleAxisd(radians.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(radians.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(radians.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix4d ComposeTransform(const Eigen::Vector3d& translate, const Eigen::Vector3d& rotate_deg,
                                 const Eigen::Vector3d& scale) {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  transform.topLeftCorner<3, 3>() = RotationFromEulerDegrees(rotate_deg) * scale.asDiagonal();
  transform.topRightCorner<3, 1>() = translate;
  return transform;
}

TriangleMesh TransformMesh(const TriangleMesh& mesh, const Eigen::Matrix4d& b_from_a) {
  TriangleMesh result = mesh;
  for (auto& vertex : result.vertices) vertex = TransformPoint(b_from_a, vertex);
  const Eigen::Matrix3d normal_matrix = b_from_a.topLeftCorner<3, 3>().inverse().transpose();
  for (auto& normal : result.vertex_normals) {
    normal = (normal_matrix * normal.cast<double>()).normalized().cast<float>();
  }
  // A mirroring transform flips the winding; restore counter-clockwise fronts.
  if (b_from_a.topLeftCorner<3, 3>().determinant() < 0) {
    for (auto& triangle : result.triangles) std::swap(triangle[1], triangle[2]);
    for (auto& corners : result.triangle_texcoords) std::swap(corners[1], corners[2]);
  }
  return result;
}

PointCloud TransformPointCloud(const PointCloud& cloud, const Eigen::Matrix4d& b_from_a) {
  PointCloud result = cloud;
  for (auto& point : result.points) point = TransformPoint(b_from_a, point);
  const Eigen::Matrix3d normal_matrix = b_from_a.topLeftCorner<3, 3>().inverse().transpose();
  for (auto& normal : result.normals)
    normal = (normal_matrix * normal.cast<double>()).normalized().cast<float>();
  return result;
}

bool IsRigid(const Eigen::Matrix4d& transform, double tolerance) {
  const Eigen::Matrix3d rotation = transform.topLeftCorner<3, 3>();
  const bool orthonormal = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() < tolerance;
  const bool proper = std::abs(rotation.determinant() - 1.0) < tolerance;
  const bool affine_row = (transform.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() < tolerance;
  return orthonormal && proper && affine_row;
}

std::string PoseProblem(const Eigen::Matrix4d& pose, bool allow_uniform_scale) {
  if (!pose.allFinite()) return "has a non-finite entry";
  if (!pose.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9)) return "last row is not 0 0 0 1";
  if (pose.topRightCorner<3, 1>().cwiseAbs().maxCoeff() > kMaxCoordinateM) {
    return fmt::format("translation {} {} {} is beyond {} m", pose(0, 3), pose(1, 3), pose(2, 3),
                       kMaxCoordinateM);
  }
  const Eigen::Matrix3d linear = pose.topLeftCorner<3, 3>();
  const double det = linear.determinant();
  if (!(det > 0)) return det < 0 ? "is mirrored (determinant < 0)" : "is singular (determinant 0)";
  const double scale = std::cbrt(det);
  if (scale < 1e-6 || scale > 1e6) return fmt::format("scale {} is outside [1e-6, 1e6]", scale);
  if (!allow_uniform_scale && std::abs(scale - 1) > 1e-4) {
    return fmt::format("is scaled by {} (a rotation was expected)", scale);
  }
  const Eigen::Matrix3d rotation = linear / scale;
  if (!(rotation.transpose() * rotation).isApprox(Eigen::Matrix3d::Identity(), 1e-4)) {
    return "is sheared or scaled per axis (the 3x3 part is not a rotation times one scale)";
  }
  return "";
}

Eigen::Matrix4d RoundedPose(const Eigen::Matrix4d& pose) {
  constexpr double kStep = 1e-9;
  Eigen::Matrix4d rounded = pose;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      const double value = pose(r, c);
      if (!std::isfinite(value)) continue;
      rounded(r, c) = std::round(value / kStep) * kStep;
      if (rounded(r, c) == 0.0) rounded(r, c) = 0.0;  // no -0
    }
  }
  return rounded;
}

}  // namespace lidarshop
