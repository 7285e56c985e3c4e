// Small synthetic scenes for the verify tests and the verify experiment (header only, no gtest).
//
// A noise-free synthetic scan is RaycastScene::CastImage over
// DirectionsFromGrid(UniformGrid(...)): these helpers build boxes, a simple two-box car and such
// scans, so that the verify module can be tested on its own.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop::verify_testing {

inline double Radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// An axis-aligned box [min, max], each face split into `n` x `n` quads (2 n²
// triangles per face), outward normals.
inline TriangleMesh MakeBox(const Eigen::Vector3f& min, const Eigen::Vector3f& max, int n = 1) {
  TriangleMesh mesh;
  const Eigen::Vector3f size = max - min;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u_axis = (axis + 1) % 3;
      const int v_axis = (axis + 2) % 3;
      const int base = static_cast<int>(mesh.vertices.size());
      for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
          Eigen::Vector3f p = min;
          p[axis] += side * size[axis];
          p[u_axis] += size[u_axis] * i / n;
          p[v_axis] += size[v_axis] * j / n;
          mesh.vertices.push_back(p);
        }
      }
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const int a = base + i * (n + 1) + j, b = a + (n + 1), c = b + 1, d = a + 1;
          // (u x v) = +axis: counter-clockwise a, b, c seen from +axis.
          if (side == 1) {
            mesh.triangles.emplace_back(a, b, c);
            mesh.triangles.emplace_back(a, c, d);
          } else {
            mesh.triangles.emplace_back(a, c, b);
            mesh.triangles.emplace_back(a, d, c);
          }
        }
      }
    }
  }
  return mesh;
}

// A two-box "car" in its model frame: x forward (length), y left (width), z up, origin at the ground centre.
// Body from z = 0.3·h to 0.6·h over the full length, cabin from 0.6·h to h over the middle 55 %; wheels are
// left out (the body floats like a real car's sill above the ground).
inline TriangleMesh MakeCar(float length = 4.5f, float width = 1.8f, float height = 1.5f, int n = 8) {
  TriangleMesh car = MakeBox(Eigen::Vector3f(-length / 2, -width / 2, 0.3f * height),
                             Eigen::Vector3f(length / 2, width / 2, 0.6f * height), n);
  AppendMesh(MakeBox(Eigen::Vector3f(-0.3f * length, -width / 2 + 0.05f, 0.6f * height),
                     Eigen::Vector3f(0.25f * length, width / 2 - 0.05f, height), n),
             &car);
  return car;
}

// A scene mesh with a label per mesh.
struct LabeledMesh {
  TriangleMesh mesh_in_world;
  int32_t label = 0;
};

// Noise-free scan of `meshes` from `world_from_scanner` over a uniform grid (angles in degrees).
inline Scan SyntheticScan(const std::vector<LabeledMesh>& meshes, const Eigen::Matrix4d& world_from_scanner,
                          int rows, int cols, double azimuth_min_deg, double azimuth_max_deg,
                          double elevation_min_deg, double elevation_max_deg) {
  RaycastScene scene;
  const Eigen::Matrix4d scanner_from_world = world_from_scanner.inverse();
  for (size_t m = 0; m < meshes.size(); ++m) {
    scene.AddMesh(TransformMesh(meshes[m].mesh_in_world, scanner_from_world), static_cast<int32_t>(m));
  }
  scene.Commit();
  Scan scan = MakeScan(rows, cols);
  scan.world_from_scanner = world_from_scanner;
  scan.grid = UniformGrid(rows, cols, Radians(azimuth_min_deg), Radians(azimuth_max_deg),
                          Radians(elevation_min_deg), Radians(elevation_max_deg));
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.label = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNoLabel));
  const RayHitImages hits = scene.CastImage(Eigen::Vector3f(Eigen::Vector3f::Zero()), scan.direction);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int32_t id = hits.geometry_id.at<int32_t>(r, c);
      if (id == kInvalidId) continue;
      const float t = hits.t_hit.at<float>(r, c);
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(r, c);
      scan.valid.at<uint8_t>(r, c) = kValid;
      scan.range.at<float>(r, c) = t;
      scan.point.at<cv::Vec3f>(r, c) = d * t;
      scan.label.at<int32_t>(r, c) = meshes[id].label;
    }
  }
  return scan;
}

}  // namespace lidarshop::verify_testing
