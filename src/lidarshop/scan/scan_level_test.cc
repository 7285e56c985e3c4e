#include "lidarshop/scan/scan_level.h"

#include <gtest/gtest.h>

namespace lidarshop {
namespace {

// A 5 x 5 scan whose range is 10 · row + col (+1, so 0 stays "no return"), with a colour channel and a grid.
Scan MakeNumberedScan() {
  Scan scan = MakeScan(5, 5, /*with_color=*/true, /*with_intensity=*/false);
  scan.grid = UniformGrid(5, 5, -0.4, 0.4, -0.2, 0.2);
  scan.direction = DirectionsFromGrid(scan.grid);
  for (int row = 0; row < 5; ++row) {
    for (int col = 0; col < 5; ++col) {
      const float range = static_cast<float>(10 * row + col + 1);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.range.at<float>(row, col) = range;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(static_cast<uint8_t>(row), static_cast<uint8_t>(col), 7);
    }
  }
  return scan;
}

TEST(ScanLevelTest, EachCoarseCellIsTheReturnNearestItsBlocksCentre) {
  Scan scan = MakeNumberedScan();
  // Block (0, 0) = rows 0-1 x cols 0-1: its four cells are equally near the centre, the first in row-major
  // order that has a return is taken.
  scan.valid.at<uint8_t>(0, 0) = 0;
  scan.range.at<float>(0, 0) = 0;
  // Block (1, 1) = rows 2-3 x cols 2-3 without any return: its centre cell (2, 2) with no return.
  for (int row = 2; row < 4; ++row) {
    for (int col = 2; col < 4; ++col) {
      scan.valid.at<uint8_t>(row, col) = 0;
      scan.range.at<float>(row, col) = 0;
    }
  }
  const Scan level = DecimateScan(scan, 2);
  ASSERT_EQ(level.rows, 3);  // ceil(5 / 2): the last block is one row and column
  ASSERT_EQ(level.cols, 3);
  EXPECT_FLOAT_EQ(level.range.at<float>(0, 0), 2.0f);  // cell (0, 1)
  EXPECT_FLOAT_EQ(level.range.at<float>(0, 1), 3.0f);  // cell (0, 2)
  EXPECT_EQ(level.valid.at<uint8_t>(1, 1), 0);
  EXPECT_FLOAT_EQ(level.range.at<float>(1, 1), 0.0f);
  EXPECT_FLOAT_EQ(level.range.at<float>(2, 2), 45.0f);  // the lone corner cell (4, 4)
  // Every channel comes from the same cell, the direction included (also without a return).
  EXPECT_EQ(level.color.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 1, 7));
  EXPECT_EQ(level.color.at<cv::Vec3b>(2, 1), cv::Vec3b(4, 2, 7));
  EXPECT_EQ(level.direction.at<cv::Vec3f>(1, 1), scan.direction.at<cv::Vec3f>(2, 2));
  EXPECT_EQ(level.point.at<cv::Vec3f>(2, 1), scan.point.at<cv::Vec3f>(4, 2));
  // Channels the scan does not have stay absent.
  EXPECT_TRUE(level.intensity.empty());
  EXPECT_TRUE(level.label.empty());
  // The grid: the blocks' centre rows and columns (the first of two).
  ASSERT_EQ(level.grid.azimuth_rad.size(), 3u);
  EXPECT_DOUBLE_EQ(level.grid.azimuth_rad[1], scan.grid.azimuth_rad[2]);
  EXPECT_DOUBLE_EQ(level.grid.elevation_rad[2], scan.grid.elevation_rad[4]);
  const cv::Mat cells = DecimatedCells(scan, 2);
  EXPECT_EQ(cells.at<int32_t>(0, 0), 1);
  EXPECT_EQ(cells.at<int32_t>(1, 1), 2 * 5 + 2);
}

TEST(ScanLevelTest, OddFactorsTakeTheCentreAndFactorOneCopies) {
  const Scan scan = MakeNumberedScan();
  const Scan level = DecimateScan(scan, 3);
  ASSERT_EQ(level.rows, 2);
  EXPECT_FLOAT_EQ(level.range.at<float>(0, 0), 12.0f);  // cell (1, 1), the 3 x 3 block's centre
  EXPECT_FLOAT_EQ(level.range.at<float>(1, 1), 45.0f);  // block rows 3-4 x cols 3-4: its centre is (4, 4)
  const Scan copy = DecimateScan(scan, 1);
  EXPECT_EQ(cv::countNonZero(copy.range != scan.range), 0);
  EXPECT_THROW(DecimateScan(scan, 0), std::invalid_argument);
}

}  // namespace
}  // namespace lidarshop
