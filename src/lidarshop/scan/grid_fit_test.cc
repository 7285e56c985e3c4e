#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/scan/scan.h"

namespace lidarshop {
namespace {

// A scan of a sphere of radius 10 around the scanner on a uniform grid, with orthogonal noise
// `sigma_rad` (radians) on each point's direction, `hole_fraction` of the cells without a return,
// and whole empty columns and rows.
Scan SyntheticScan(const ScanGrid& truth, double sigma_rad, double hole_fraction,
                   const std::vector<int>& empty_cols, const std::vector<int>& empty_rows, uint32_t seed) {
  const int rows = static_cast<int>(truth.elevation_rad.size());
  const int cols = static_cast<int>(truth.azimuth_rad.size());
  Scan scan = MakeScan(rows, cols);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma_rad);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (uniform(random) < hole_fraction) continue;
      if (std::find(empty_cols.begin(), empty_cols.end(), col) != empty_cols.end()) continue;
      if (std::find(empty_rows.begin(), empty_rows.end(), row) != empty_rows.end()) continue;
      const Eigen::Vector3f direction = DirectionFromAngles(truth.azimuth_rad[col] + noise(random),
                                                            truth.elevation_rad[row] + noise(random));
      const Eigen::Vector3f point = direction * 10.0f;
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = cv::Vec3f(point.x(), point.y(), point.z());
      scan.range.at<float>(row, col) = 10.0f;
    }
  }
  return scan;
}

double MaxAngleError(const cv::Mat& a, const cv::Mat& b) {
  double worst = 0;
  for (int row = 0; row < a.rows; ++row) {
    for (int col = 0; col < a.cols; ++col) {
      const cv::Vec3d u(a.at<cv::Vec3f>(row, col)), v(b.at<cv::Vec3f>(row, col));
      worst = std::max(worst, std::atan2(cv::norm(u.cross(v)), u.dot(v)));
    }
  }
  return worst;
}

TEST(GridFitTest, NoiseFreeGridIsRecoveredExactly) {
  const ScanGrid truth = UniformGrid(40, 60, -0.8, 0.8, -0.5, 0.4);
  Scan scan = SyntheticScan(truth, 0.0, 0.3, {}, {}, 1);
  FitGrid(&scan);
  ASSERT_TRUE(scan.grid.fitted);
  ASSERT_EQ(scan.grid.azimuth_rad.size(), 60u);
  ASSERT_EQ(scan.grid.elevation_rad.size(), 40u);
  for (int col = 0; col < 60; ++col) EXPECT_NEAR(scan.grid.azimuth_rad[col], truth.azimuth_rad[col], 1e-6);
  for (int row = 0; row < 40; ++row)
    EXPECT_NEAR(scan.grid.elevation_rad[row], truth.elevation_rad[row], 1e-6);
  EXPECT_LT(scan.grid.rms_residual_rad, 1e-6);
  EXPECT_LT(MaxAngleError(scan.direction, DirectionsFromGrid(truth)), 1e-6);
}

TEST(GridFitTest, NoisyGridWithHolesAndEmptyLines) {
  // Step 0.01 rad; noise 1 mrad; 40 % of cells empty; empty columns inside and at
  // both ends, empty rows likewise.
  const ScanGrid truth = UniformGrid(80, 120, -0.6, 0.59, -0.4, 0.39);
  const double sigma = 0.001;
  Scan scan = SyntheticScan(truth, sigma, 0.4, {0, 1, 50, 51, 52, 119}, {0, 30, 79}, 7);
  FitGrid(&scan);
  ASSERT_TRUE(scan.grid.fitted);
  // Every cell, also without a return, gets a direction close to the true grid.
  EXPECT_LT(MaxAngleError(scan.direction, DirectionsFromGrid(truth)), 0.002);
  // The azimuths are increasing and the elevations decreasing down the image.
  for (int col = 1; col < 120; ++col) EXPECT_GT(scan.grid.azimuth_rad[col], scan.grid.azimuth_rad[col - 1]);
  for (int row = 1; row < 80; ++row)
    EXPECT_LT(scan.grid.elevation_rad[row], scan.grid.elevation_rad[row - 1]);
  // The residual measures the noise: 2-D angular noise of sigma per axis has RMS sqrt(2) sigma.
  EXPECT_NEAR(scan.grid.rms_residual_rad, std::sqrt(2.0) * sigma, 0.15 * sigma);
  EXPECT_GT(scan.grid.max_residual_rad, scan.grid.rms_residual_rad);
  // A no-return cell has the direction of its grid cell.
  const cv::Vec3f d = scan.direction.at<cv::Vec3f>(30, 50);
  EXPECT_NEAR(d[0], DirectionFromAngles(truth.azimuth_rad[50], truth.elevation_rad[30]).x(), 2e-3);
}

TEST(GridFitTest, OutlierColumnIsRejected) {
  // One column holds a single point far off its true azimuth (a stray return): it must not bend the grid.
  const ScanGrid truth = UniformGrid(30, 30, -0.3, 0.3, -0.3, 0.3);
  Scan scan = SyntheticScan(truth, 0.0, 0.0, {10}, {}, 3);
  const Eigen::Vector3f stray =
      DirectionFromAngles(truth.azimuth_rad[10] + 0.05, truth.elevation_rad[15]) * 5.0f;
  scan.valid.at<uint8_t>(15, 10) = kValid;
  scan.point.at<cv::Vec3f>(15, 10) = cv::Vec3f(stray.x(), stray.y(), stray.z());
  FitGrid(&scan);
  EXPECT_NEAR(scan.grid.azimuth_rad[10], truth.azimuth_rad[10], 1e-6);
  EXPECT_NEAR(scan.grid.max_residual_rad, 0.05, 1e-3);  // the stray point shows in the residual
}

TEST(GridFitTest, FullTurnAcrossMinusPi) {
  // 360° scan whose columns cross θ = ±π: azimuths must stay continuous.
  const ScanGrid truth = UniformGrid(10, 360, 0.5, 0.5 + 2 * M_PI * 359 / 360, -0.2, 0.2);
  Scan scan = SyntheticScan(truth, 0.0005, 0.2, {}, {}, 5);
  FitGrid(&scan);
  EXPECT_LT(MaxAngleError(scan.direction, DirectionsFromGrid(truth)), 0.002);
  for (int col = 1; col < 360; ++col) EXPECT_GT(scan.grid.azimuth_rad[col], scan.grid.azimuth_rad[col - 1]);
}

TEST(GridFitTest, SingleValidCellAndEmptyScan) {
  Scan empty = MakeScan(5, 5);
  FitGrid(&empty);
  EXPECT_FALSE(empty.grid.fitted);
  const ScanGrid truth = UniformGrid(5, 5, -0.1, 0.1, -0.1, 0.1);
  Scan one = SyntheticScan(truth, 0.0, 0.0, {0, 1, 3, 4}, {0, 1, 3, 4}, 1);
  ASSERT_EQ(one.CountValid(), 1);
  FitGrid(&one);
  ASSERT_TRUE(one.grid.fitted);
  EXPECT_NEAR(one.grid.azimuth_rad[2], truth.azimuth_rad[2], 1e-6);
  EXPECT_NEAR(one.grid.elevation_rad[2], truth.elevation_rad[2], 1e-6);
}

}  // namespace
}  // namespace lidarshop
