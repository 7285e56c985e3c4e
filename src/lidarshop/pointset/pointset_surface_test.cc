// Surface reconstruction on clouds whose surface is known: a sphere (closed) and a plane patch (open).
#include <cmath>
#include <map>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "lidarshop/pointset/surface.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Points on the unit sphere around (1, 2, 3), with outward normals when asked.
PointCloud Sphere(int count, bool with_normals) {
  std::mt19937 rng(4);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  PointCloud cloud;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f direction = Eigen::Vector3f(normal(rng), normal(rng), normal(rng)).normalized();
    cloud.points.push_back(Eigen::Vector3f(1, 2, 3) + direction);
    if (with_normals) cloud.normals.push_back(direction);
  }
  return cloud;
}

double LargestRadiusError(const TriangleMesh& mesh) {
  double worst = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    worst = std::max(worst, std::abs(static_cast<double>((v - Eigen::Vector3f(1, 2, 3)).norm()) - 1.0));
  }
  return worst;
}

// Every edge of a closed manifold mesh is shared by exactly two triangles.
bool Watertight(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, count] : edges) {
    if (count != 2) return false;
  }
  return !edges.empty();
}

TEST(SurfaceTest, PoissonClosesASphere) {
  const PointCloud cloud = Sphere(4000, true);
  const TriangleMesh mesh = ReconstructSurface(cloud, {.method = SurfaceMethod::kPoisson});
  EXPECT_GT(mesh.num_triangles(), 500u);
  EXPECT_LT(LargestRadiusError(mesh), 0.03);
  EXPECT_TRUE(Watertight(mesh));
  // Normals estimated from the points and turned toward a viewpoint inside give the same kind of surface.
  PointCloud bare = cloud;
  bare.normals.clear();
  const TriangleMesh estimated =
      ReconstructSurface(bare, {.method = SurfaceMethod::kPoisson, .viewpoint = Eigen::Vector3f(1, 2, 3)});
  EXPECT_LT(LargestRadiusError(estimated), 0.05);
  // The same input gives the same mesh.
  const TriangleMesh again = ReconstructSurface(cloud, {.method = SurfaceMethod::kPoisson});
  ASSERT_EQ(again.num_triangles(), mesh.num_triangles());
  EXPECT_EQ(again.vertices, mesh.vertices);
}

TEST(SurfaceTest, ScaleSpaceInterpolatesThePoints) {
  const PointCloud cloud = Sphere(3000, false);
  const TriangleMesh mesh = ReconstructSurface(cloud, {.method = SurfaceMethod::kScaleSpace});
  EXPECT_GT(mesh.num_triangles(), 3000u);
  EXPECT_LT(LargestRadiusError(mesh), 1e-6);  // the vertices are input points
  const TriangleMesh again = ReconstructSurface(cloud, {.method = SurfaceMethod::kScaleSpace});
  EXPECT_EQ(again.triangles, mesh.triangles);
  // Facing out of the sphere (centred on the origin): CGAL's advancing front started from an address-dependent
  // facet and came back reversed in some runs.
  double volume = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    volume += mesh.vertices[t[0]].cast<double>().dot(
        mesh.vertices[t[1]].cast<double>().cross(mesh.vertices[t[2]].cast<double>()));
  }
  EXPECT_GT(volume, 0);
}

TEST(SurfaceTest, KeepWithinTrimsTheMembraneOfAnOpenDome) {
  // The upper half of the sphere (an open surface, like a scan): Poisson closes it with a membrane below.
  PointCloud dome;
  const PointCloud sphere = Sphere(6000, true);
  for (size_t i = 0; i < sphere.size(); ++i) {
    if (sphere.points[i].z() >= 3.0f) {
      dome.points.push_back(sphere.points[i]);
      dome.normals.push_back(sphere.normals[i]);
    }
  }
  const TriangleMesh closed = ReconstructSurface(dome, {.method = SurfaceMethod::kPoisson});
  const TriangleMesh trimmed =
      ReconstructSurface(dome, {.method = SurfaceMethod::kPoisson, .keep_within_m = 0.1});
  ASSERT_GT(trimmed.num_triangles(), 100u);
  EXPECT_LT(trimmed.num_triangles(), closed.num_triangles());
  float lowest_closed = 10, lowest_trimmed = 10;
  for (const Eigen::Vector3f& v : closed.vertices) lowest_closed = std::min(lowest_closed, v.z());
  for (const Eigen::Vector3f& v : trimmed.vertices) lowest_trimmed = std::min(lowest_trimmed, v.z());
  EXPECT_LT(lowest_closed, 2.9f);    // the membrane reaches below the dome's rim
  EXPECT_GT(lowest_trimmed, 2.85f);  // trimmed: only what lies near the points
}

TEST(SurfaceTest, BadInputIsRefused) {
  PointCloud few;
  for (int i = 0; i < 5; ++i) few.points.emplace_back(i, 0, 0);
  EXPECT_THROW(ReconstructSurface(few), InputError);
  PointCloud nan = Sphere(100, true);
  nan.points[3].x() = std::nanf("");
  EXPECT_THROW(ReconstructSurface(nan), InputError);
  PointCloud mismatched = Sphere(100, true);
  mismatched.normals.pop_back();
  EXPECT_THROW(ReconstructSurface(mismatched), InputError);
  EXPECT_THROW(ReconstructSurface(Sphere(100, true), {.poisson_angle_deg = 0}), OptionsError);
  // Exactly on one plane: refused (a 3-D triangulation of it has no cells), not a crash.
  PointCloud flat;
  for (int i = 0; i < 200; ++i) flat.points.emplace_back(i % 20, i / 20, 1.0f);
  EXPECT_THROW(ReconstructSurface(flat, {.method = SurfaceMethod::kPoisson}), InputError);
  EXPECT_THROW(ReconstructSurface(flat, {.method = SurfaceMethod::kScaleSpace}), InputError);
}

}  // namespace
}  // namespace lidarshop
