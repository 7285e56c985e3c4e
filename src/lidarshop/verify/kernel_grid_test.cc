#include "lidarshop/verify/kernel_grid.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace lidarshop::verify_internal {
namespace {

// Model points on the surface of a 2 x 1 x 0.8 m box; scene points on a noisy, slightly shifted copy of
// its top and front, in scan order (rows of neighbouring points), plus points scattered around it.
struct Fixture {
  std::vector<Eigen::Vector3f> model_points;
  std::vector<Eigen::Vector3f> scene_points;
  Eigen::AlignedBox3f bounds{Eigen::Vector3f(-1, -0.5f, 0), Eigen::Vector3f(1, 0.5f, 0.8f)};

  Fixture() {
    std::mt19937 random(3);
    std::uniform_real_distribution<float> unit(0, 1);
    for (int i = 0; i < 4000; ++i) {
      Eigen::Vector3f p = bounds.min() + bounds.sizes().cwiseProduct(
                                             Eigen::Vector3f(unit(random), unit(random), unit(random)));
      const int face = i % 6;
      p[face / 2] = face % 2 ? bounds.max()[face / 2] : bounds.min()[face / 2];
      model_points.push_back(p);
    }
    std::normal_distribution<float> noise(0, 0.01f);
    for (int row = 0; row < 60; ++row) {
      for (int col = 0; col < 120; ++col) {
        const float x = -1.1f + 2.2f * col / 119;
        if (row < 30) {
          scene_points.emplace_back(x + noise(random), -0.5f + row / 30.0f, 0.8f + noise(random));
        } else {
          scene_points.emplace_back(x + noise(random), -0.5f + noise(random), 0.8f * (row - 30) / 30.0f);
        }
      }
    }
    const Eigen::Vector3f lo = bounds.min().array() - 0.3f, extent = bounds.sizes().array() + 0.6f;
    for (int i = 0; i < 3000; ++i) {
      scene_points.push_back(lo +
                             extent.cwiseProduct(Eigen::Vector3f(unit(random), unit(random), unit(random))));
    }
  }
};

constexpr float kSigma = 0.03f, kTrim = 0.2f;

TEST(KernelGridTest, KernelExpIsWithinTwoUlpOfStdExp) {
  float worst = 0;
  for (float x = -87.0f; x <= 0.0f; x += 0.000731f) {
    const float expected = std::exp(x), actual = KernelExp(x);
    worst = std::max(worst, std::abs(actual - expected) / (expected * std::numeric_limits<float>::epsilon()));
  }
  EXPECT_LE(worst, 2.0f);
  EXPECT_EQ(KernelExp(0.0f), 1.0f);
}

TEST(KernelGridTest, ScalarAndAvx2PathsAreBitIdenticalAndMatchBruteForce) {
  const Fixture fixture;
  const KernelNeighbourGrid grid = BuildKernelGrid(fixture.model_points, fixture.bounds, 3 * kSigma, kTrim);
  const size_t n = fixture.model_points.size(), m = fixture.scene_points.size();
  const float radius_sq = 9 * kSigma * kSigma, inverse_two_sigma_sq = 1 / (2 * kSigma * kSigma);

  std::vector<float> sum_scalar(n, 0), closest_scalar(m), sum_avx2(n, 0), closest_avx2(m);
  AccumulateKernel(grid, fixture.scene_points, radius_sq, inverse_two_sigma_sq, sum_scalar.data(),
                   closest_scalar.data(), SimdPath::kScalar);
  AccumulateKernel(grid, fixture.scene_points, radius_sq, inverse_two_sigma_sq, sum_avx2.data(),
                   closest_avx2.data(), SimdPath::kAvx2);
  std::vector<float> nearest_scalar(m), nearest_avx2(m);
  NearestSquaredDistance(grid, fixture.scene_points, nearest_scalar.data(), SimdPath::kScalar);
  NearestSquaredDistance(grid, fixture.scene_points, nearest_avx2.data(), SimdPath::kAvx2);

  // Brute force, by model point index and in the original scene order.
  std::vector<float> sum_reference(n, 0);
  int saturated = 0, unsaturated_seen = 0, inliers = 0;
  for (size_t j = 0; j < m; ++j) {
    const Eigen::Vector3f& p = fixture.scene_points[j];
    float closest = std::numeric_limits<float>::infinity(), nearest = closest;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f d = fixture.model_points[i] - p;
      const float distance_sq = (d.x() * d.x() + d.y() * d.y()) + d.z() * d.z();
      nearest = std::min(nearest, distance_sq);
      if (distance_sq < radius_sq) {
        closest = std::min(closest, distance_sq);
        if (sum_reference[i] < 1) sum_reference[i] += std::exp(-distance_sq * inverse_two_sigma_sq);
      }
    }
    ASSERT_EQ(closest_scalar[j], closest) << "scene point " << j;
    ASSERT_EQ(closest_avx2[j], closest) << "scene point " << j;
    if (nearest <= kTrim * kTrim) {
      ++inliers;
      ASSERT_EQ(nearest_scalar[j], nearest) << "scene point " << j;
      ASSERT_EQ(nearest_avx2[j], nearest) << "scene point " << j;
    } else {
      ASSERT_GT(nearest_scalar[j], kTrim * kTrim);
      ASSERT_GT(nearest_avx2[j], kTrim * kTrim);
    }
  }
  for (size_t k = 0; k < n; ++k) {
    ASSERT_EQ(sum_scalar[k], sum_avx2[k]) << "slot " << k;
    const uint32_t i = grid.kernel.indices[k];
    // Another summation order: equal up to rounding once clamped to 1, as the measure uses it.
    ASSERT_NEAR(std::min(1.0f, sum_scalar[k]), std::min(1.0f, sum_reference[i]), 1e-5f)
        << "model point " << i;
    saturated += sum_reference[i] >= 1;
    unsaturated_seen += sum_reference[i] > 0 && sum_reference[i] < 1;
  }
  // The fixture exercises every case.
  EXPECT_GT(saturated, 500);
  EXPECT_GT(unsaturated_seen, 50);
  EXPECT_GT(inliers, 5000);
  EXPECT_LT(inliers, static_cast<int>(m));
}

}  // namespace
}  // namespace lidarshop::verify_internal
