// PointKdTree against brute force, and surface sampling (determinism, uniformity over area).
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/pointset/sampling.h"

namespace lidarshop {
namespace {

std::vector<Eigen::Vector3f> RandomPoints(int count, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> points(count);
  for (auto& p : points) p = Eigen::Vector3f(uniform(random), uniform(random), uniform(random));
  return points;
}

TEST(PointKdTreeTest, MatchesBruteForce) {
  const std::vector<Eigen::Vector3f> points = RandomPoints(2000, 1);
  const PointKdTree tree(points);
  ASSERT_EQ(tree.size(), points.size());
  for (const Eigen::Vector3f& query : RandomPoints(50, 2)) {
    std::vector<std::pair<float, uint32_t>> all;
    for (uint32_t i = 0; i < points.size(); ++i) all.emplace_back((points[i] - query).squaredNorm(), i);
    std::sort(all.begin(), all.end());
    const NearestResult nearest = tree.Nearest(query);
    EXPECT_EQ(nearest.index, all[0].second);
    EXPECT_FLOAT_EQ(nearest.distance_sq, all[0].first);
    const NearestResult within = tree.NearestWithin(query, 0.05f);
    EXPECT_EQ(within.found(), all[0].first < 0.05f * 0.05f);
    std::vector<uint32_t> indices;
    std::vector<float> distances;
    tree.KNearest(query, 5, &indices, &distances);
    ASSERT_EQ(indices.size(), 5u);
    for (int k = 0; k < 5; ++k) EXPECT_EQ(indices[k], all[k].second);
    const float radius = 0.2f;
    size_t expected = 0;
    while (expected < all.size() && all[expected].first < radius * radius) ++expected;
    std::vector<std::pair<uint32_t, float>> matches;
    tree.RadiusSearch(query, radius, &matches, true);
    EXPECT_EQ(matches.size(), expected);
    size_t visited = 0;
    tree.ForEachInRadius(query, radius, [&](uint32_t, float distance_sq) {
      EXPECT_LT(distance_sq, radius * radius);
      ++visited;
    });
    EXPECT_EQ(visited, expected);
  }
}

TEST(PointKdTreeTest, EmptyAndMovedTreesWork) {
  const PointKdTree empty;
  EXPECT_FALSE(empty.Nearest(Eigen::Vector3f::Zero()).found());
  PointKdTree tree(RandomPoints(100, 3));
  PointKdTree moved = std::move(tree);
  EXPECT_TRUE(moved.Nearest(Eigen::Vector3f::Zero()).found());
}

TEST(SampleSurfaceTest, DeterministicAndUniformOverArea) {
  // Two triangles: the second has three times the area of the first.
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {5, 0, 0}, {2, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
  const SurfaceSamples a = SampleSurface(mesh, 20000, 7);
  const SurfaceSamples b = SampleSurface(mesh, 20000, 7);
  const SurfaceSamples c = SampleSurface(mesh, 20000, 8);
  ASSERT_EQ(a.points.size(), 20000u);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
  const auto on_second = std::count(a.triangle_ids.begin(), a.triangle_ids.end(), 1);
  EXPECT_NEAR(on_second / 20000.0, 0.75, 0.02);
  for (size_t s = 0; s < a.points.size(); ++s) {
    const Eigen::Vector3f& p = a.points[s];
    EXPECT_EQ(p.z(), 0.0f);
    if (a.triangle_ids[s] == 0) EXPECT_LE(p.x() + p.y(), 1.0f + 1e-5f);
  }
  EXPECT_TRUE(SampleSurface(TriangleMesh(), 10, 1).points.empty());
}

}  // namespace
}  // namespace lidarshop
