// Rigid and similarity transforms. Names carry frames: `world_from_model` maps
// model coordinates to world ones.
//
// Conventions shared by scene files, the CLI, the server and the Python module: an object is scaled, then
// rotated, then translated. Rotations given as angles have ONE convention everywhere
// (RotationFromEulerDegrees below is the only place where angles become a rotation):
//   R = Rz(yaw) · Ry(pitch) · Rx(roll)
// roll about x is applied first, then pitch about y, then yaw about z, all about the fixed axes of the outer
// frame; positive angles turn counter-clockwise seen from the axis' positive end (yaw turns +x towards +y).
// `rotate_deg` = [x, y, z] = [roll, pitch, yaw] in degrees.
#pragma once

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop {

// R = Rz(yaw) · Ry(pitch) · Rx(roll) for rotate_deg = [roll, pitch, yaw] = [x, y, z], degrees.
Eigen::Matrix3d RotationFromEulerDegrees(const Eigen::Vector3d& rotate_deg);

// 4x4 matrix of translate * rotate * scale (scale per axis).
Eigen::Matrix4d ComposeTransform(const Eigen::Vector3d& translate, const Eigen::Vector3d& rotate_deg,
                                 const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

// Applies a 4x4 affine transform to positions (normals by the inverse transpose, renormalized).
TriangleMesh TransformMesh(const TriangleMesh& mesh, const Eigen::Matrix4d& b_from_a);
PointCloud TransformPointCloud(const PointCloud& cloud, const Eigen::Matrix4d& b_from_a);

inline Eigen::Vector3f TransformPoint(const Eigen::Matrix4d& b_from_a, const Eigen::Vector3f& point_in_a) {
  return (b_from_a.topLeftCorner<3, 3>() * point_in_a.cast<double>() + b_from_a.topRightCorner<3, 1>())
      .cast<float>();
}

// True when the top-left 3x3 is a rotation (orthonormal, det +1) within `tolerance` and the last row is
// 0 0 0 1.
bool IsRigid(const Eigen::Matrix4d& transform, double tolerance = 1e-6);

// The largest coordinate or translation (metres) lidarshop accepts: terrestrial scenes span kilometres, so a
// value past this is corrupt data (1e38 sentinels, overflowed numbers) — and Embree asserts on such values.
constexpr double kMaxCoordinateM = 1e7;

// Why `pose` is not a usable pose, or "" when it is: every entry finite, last row 0 0 0 1, translation within
// kMaxCoordinateM, top-left 3x3 a rotation (det +1, no shear, no mirror) times one uniform scale in
// [1e-6, 1e6] when `allow_uniform_scale`, else a rotation within 1e-4.
std::string PoseProblem(const Eigen::Matrix4d& pose, bool allow_uniform_scale);

// `pose` as results report it to people: every entry rounded to a multiple of 1e-9 (a nanometre for the
// translation), which also drops a rotation's 1e-17 noise (1.0000000000000002 becomes 1), and -0 made 0;
// non-finite entries stay. The same numbers as io's MatrixJson (io/scan_header.h) writes.
Eigen::Matrix4d RoundedPose(const Eigen::Matrix4d& pose);

}  // namespace lidarshop
