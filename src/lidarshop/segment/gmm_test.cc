// The Gaussian mixture of the segmentation's appearance models, on samples whose mixture is known.
#include "lidarshop/segment/gmm.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace lidarshop {
namespace {

TEST(GmmTest, RecoversTwoSeparatedComponentsIn1D) {
  // 3000 samples at −2 (σ 0.5) and 1000 at 3 (σ 0.25).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> left(-2.0, 0.5), right(3.0, 0.25);
  std::vector<Eigen::Matrix<double, 1, 1>> x;
  for (int i = 0; i < 3000; ++i) x.emplace_back(left(rng));
  for (int i = 0; i < 1000; ++i) x.emplace_back(right(rng));
  const Gmm<1> g = FitGmm<1>(x, 2, 20, 1e-6, 1);
  ASSERT_EQ(g.mean.size(), 2u);
  const int l = g.mean[0](0) < g.mean[1](0) ? 0 : 1, r = 1 - l;
  EXPECT_NEAR(g.mean[l](0), -2.0, 0.05);
  EXPECT_NEAR(g.mean[r](0), 3.0, 0.05);
  EXPECT_NEAR(std::exp(g.log_weight[l]), 0.75, 0.02);
  EXPECT_NEAR(1.0 / g.inv_cov[l](0, 0), 0.25, 0.03);  // variance 0.5²
  // A density: it integrates to 1.
  double integral = 0;
  for (double t = -8; t < 8; t += 0.001)
    integral += std::exp(g.LogDensity(Eigen::Matrix<double, 1, 1>(t))) * 0.001;
  EXPECT_NEAR(integral, 1.0, 1e-3);
}

TEST(GmmTest, SameSeedSameFitAndFewerSamplesThanComponents) {
  std::vector<Eigen::Vector3d> x;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 500; ++i) x.emplace_back(u(rng), u(rng), u(rng));
  const Gmm<3> a = FitGmm<3>(x, 5, 10, 1e-4, 42), b = FitGmm<3>(x, 5, 10, 1e-4, 42);
  ASSERT_EQ(a.mean.size(), b.mean.size());
  for (size_t j = 0; j < a.mean.size(); ++j) EXPECT_EQ(a.mean[j], b.mean[j]);
  // Two samples, five components asked: at most two components, and a finite density.
  const std::vector<Eigen::Vector3d> two = {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.9, 0.8, 0.7)};
  const Gmm<3> small = FitGmm<3>(two, 5, 10, 1e-4, 1);
  EXPECT_LE(small.mean.size(), 2u);
  EXPECT_TRUE(std::isfinite(small.LogDensity(Eigen::Vector3d(0.1, 0.2, 0.3))));
}

}  // namespace
}  // namespace lidarshop
