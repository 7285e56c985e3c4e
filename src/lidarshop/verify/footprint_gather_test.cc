#include "lidarshop/verify/footprint_gather.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace lidarshop::verify_internal {
namespace {

// A band of 4 rows x 37 columns (odd: the AVX2 path's half step) of returns around a 2 x 1 x 1 m box seen
// from 6 m, with no-return cells and rows outside the footprint.
TEST(FootprintGatherTest, ScalarAndAvx2PathsAreBitIdenticalAndKeepTheRightCells) {
  constexpr int kCols = 37, kScanCols = 500, kBandRow = 8, kFirstCol = 100;
  std::mt19937 random(5);
  std::uniform_real_distribution<float> azimuth(-0.25f, 0.25f), elevation(-0.12f, 0.12f), range(5.0f, 7.5f);
  std::vector<Eigen::Vector4f> cells(kCols * 4);
  int no_returns = 0;
  for (Eigen::Vector4f& cell : cells) {
    const float a = azimuth(random), e = elevation(random), r = range(random);
    const Eigen::Vector3f direction(std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e));
    cell << r * direction, r;
    if (random() % 7 == 0) {
      cell.setZero();
      ++no_returns;
    }
  }
  GatherFrame frame;
  frame.linear = Eigen::AngleAxisf(0.05f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  frame.origin = Eigen::Vector3f(0.3f, -6.0f, 0.2f);
  frame.model_box = Eigen::AlignedBox3f(Eigen::Vector3f(-1, -0.5f, -0.5f), Eigen::Vector3f(1, 0.5f, 0.5f));
  frame.near_box =
      Eigen::AlignedBox3f(Eigen::Vector3f(-1.2f, -0.7f, -0.7f), Eigen::Vector3f(1.2f, 0.7f, 0.7f));
  frame.allowance = 0.1f;
  const int row_begin = kBandRow + 1, row_end = kBandRow + 4;  // the band's first row is outside

  FootprintRays rays[2];
  NearPoints near[2];
  const SimdPath paths[2] = {SimdPath::kScalar, SimdPath::kAvx2};
  for (int p = 0; p < 2; ++p) {
    ReserveGather(cells.size(), rays[p], near[p]);
    GatherBand(cells.data(), kBandRow, row_begin, row_end, kFirstCol, kCols, kScanCols, frame, rays[p],
               near[p], paths[p]);
  }
  ASSERT_EQ(rays[0].size, rays[1].size);
  ASSERT_EQ(near[0].size, near[1].size);
  for (size_t k = 0; k < rays[0].size; ++k) {
    ASSERT_EQ(rays[0].dir_x[k], rays[1].dir_x[k]) << k;
    ASSERT_EQ(rays[0].dir_y[k], rays[1].dir_y[k]) << k;
    ASSERT_EQ(rays[0].dir_z[k], rays[1].dir_z[k]) << k;
    ASSERT_EQ(rays[0].t_near[k], rays[1].t_near[k]) << k;
    ASSERT_EQ(rays[0].limit[k], rays[1].limit[k]) << k;
    ASSERT_EQ(rays[0].cell[k], rays[1].cell[k]) << k;
  }
  for (size_t j = 0; j < near[0].size; ++j) {
    ASSERT_EQ(near[0].x[j], near[1].x[j]) << j;
    ASSERT_EQ(near[0].y[j], near[1].y[j]) << j;
    ASSERT_EQ(near[0].z[j], near[1].z[j]) << j;
  }

  // Reference: every cell by plain geometry (double precision; no cell here is within rounding of an edge).
  size_t expected_rays = 0, expected_near = 0;
  for (int col = 0; col < kCols; ++col) {
    for (int row = 0; row < 4; ++row) {
      const Eigen::Vector4f& cell = cells[col * 4 + row];
      const int image_row = kBandRow + row;
      if (image_row < row_begin || image_row >= row_end || !(cell.w() > 0)) continue;
      const Eigen::Vector3d point =
          (frame.linear.cast<double>() * cell.head<3>().cast<double>()) + frame.origin.cast<double>();
      const Eigen::Vector3d origin = frame.origin.cast<double>();
      const Eigen::Vector3d direction = (point - origin).normalized();
      double t0 = 0, t1 = 1e9;
      for (int i = 0; i < 3; ++i) {
        const double a = (frame.model_box.min()[i] - origin[i]) / direction[i];
        const double b = (frame.model_box.max()[i] - origin[i]) / direction[i];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
      }
      if (t0 <= t1) {
        ASSERT_LT(expected_rays, rays[0].size);
        EXPECT_EQ(rays[0].cell[expected_rays],
                  static_cast<uint32_t>(image_row * kScanCols + kFirstCol + col));
        EXPECT_NEAR(rays[0].limit[expected_rays], cell.w() - 0.1f, 1e-6f);
        ++expected_rays;
      }
      if (frame.near_box.cast<double>().contains(point)) ++expected_near;
    }
  }
  EXPECT_EQ(rays[0].size, expected_rays);
  EXPECT_EQ(near[0].size, expected_near);
  // The fixture exercises both outcomes of both tests.
  EXPECT_GT(expected_rays, 10u);
  EXPECT_LT(expected_rays, 100u);
  EXPECT_GT(expected_near, 5u);
  EXPECT_GT(no_returns, 5);
}

}  // namespace
}  // namespace lidarshop::verify_internal
