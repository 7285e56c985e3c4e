#include "lidarshop/scan/ray_directions.h"

#include <cstring>
#include <random>

#include <gtest/gtest.h>

namespace lidarshop {
namespace {

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && a.isContinuous() && b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

// A scan on a slightly irregular grid whose returns lie on their rays (with noise across the ray), and which
// holds its rays as an image.
Scan ScanOnGrid(int rows, int cols, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scan scan = MakeScan(rows, cols);
  scan.grid = UniformGrid(rows, cols, -0.8, 0.9, -0.4, 0.5);
  for (double& azimuth : scan.grid.azimuth_rad) azimuth += 1e-4 * u(rng);
  scan.direction = DirectionsFromGrid(scan.grid);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (u(rng) < 0.3) continue;
      const cv::Vec3f noise(1e-4f * static_cast<float>(u(rng) - 0.5),
                            1e-4f * static_cast<float>(u(rng) - 0.5), 0);
      const cv::Vec3f p =
          (scan.direction.at<cv::Vec3f>(row, col) + noise) * static_cast<float>(3.0 + 5.0 * u(rng));
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = p;
      scan.range.at<float>(row, col) = static_cast<float>(cv::norm(p));
    }
  }
  return scan;
}

TEST(RayDirections, TheGridsRaysAreDirectionsFromGridBitForBit) {
  const Scan held = ScanOnGrid(17, 23, 1);
  Scan grid_only = held;
  ASSERT_TRUE(ReleaseGridDirections(&grid_only));
  EXPECT_TRUE(grid_only.direction.empty());
  EXPECT_TRUE(HasRayDirections(grid_only));
  EXPECT_NO_THROW(CheckScan(grid_only));
  EXPECT_TRUE(SameBytes(DirectionImage(grid_only), held.direction));
  const RayDirections from_grid(grid_only), from_image(held);
  EXPECT_TRUE(from_grid.from_grid());
  EXPECT_FALSE(from_image.from_grid());
  for (int row = 0; row < held.rows; ++row) {
    for (int col = 0; col < held.cols; ++col) {
      const cv::Vec3f a = from_grid(row, col), b = held.direction.at<cv::Vec3f>(row, col);
      ASSERT_EQ(std::memcmp(&a, &b, sizeof(a)), 0) << row << ", " << col;
      ASSERT_EQ(from_image.At(int64_t{row} * held.cols + col), b);
    }
  }
}

TEST(RayDirections, ARayOffTheGridKeepsTheImage) {
  Scan scan = ScanOnGrid(9, 12, 2);
  scan.direction.at<cv::Vec3f>(4, 5) =
      cv::normalize(scan.direction.at<cv::Vec3f>(4, 5) + cv::Vec3f(1e-3f, 0, 0));
  const cv::Mat before = scan.direction;
  EXPECT_FALSE(ReleaseGridDirections(&scan));
  EXPECT_EQ(scan.direction.data, before.data);
  Scan no_grid = MakeScanWithoutDirections(3, 4, false, true);
  EXPECT_FALSE(HasRayDirections(no_grid));
  EXPECT_TRUE(DirectionImage(no_grid).empty());
  EXPECT_THROW(RayDirections{no_grid}, std::logic_error);
}

TEST(RayDirections, WindowsAndPastesOfAGridOnlyScanKeepNoImage) {
  Scan station = ScanOnGrid(30, 40, 3);
  const cv::Mat rays = station.direction.clone();
  ASSERT_TRUE(ReleaseGridDirections(&station));
  const cv::Rect window(7, 5, 12, 9);
  const Scan part = CropScan(station, window);
  EXPECT_TRUE(part.direction.empty());
  EXPECT_TRUE(SameBytes(DirectionImage(part), rays(window).clone()));
  // A part holding its rays (an edit that read them as an image) pastes its other channels, not its rays.
  Scan edited = part;
  edited.direction = DirectionImage(part);
  edited.range.setTo(4.0f);
  PasteScan(edited, window, &station);
  EXPECT_TRUE(station.direction.empty());
  EXPECT_EQ(station.range.at<float>(window.y, window.x), 4.0f);
}

TEST(RayDirections, FitGridWithoutAnImageFitsTheSameGridAndHoldsNone) {
  Scan held = ScanOnGrid(40, 50, 4);
  held.grid = {};
  Scan without = held;
  without.direction.release();
  FitGrid(&held);
  FitGrid(&without);
  EXPECT_TRUE(without.direction.empty());
  EXPECT_EQ(without.grid.azimuth_rad, held.grid.azimuth_rad);
  EXPECT_EQ(without.grid.elevation_rad, held.grid.elevation_rad);
  EXPECT_EQ(without.grid.rms_residual_rad, held.grid.rms_residual_rad);
  EXPECT_GT(without.grid.rms_residual_rad, 0.0);
  EXPECT_LT(without.grid.rms_residual_rad, 1e-4);
  EXPECT_TRUE(SameBytes(DirectionImage(without), held.direction));
}

}  // namespace
}  // namespace lidarshop
