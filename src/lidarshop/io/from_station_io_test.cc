// Scan::from_station (the cells filled from another station, site/from_stations.h) through every writer that
// can hold it, and the sentence of the one that cannot (PTX).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"

namespace lidarshop {
namespace {

using testing::Contains;
using testing::HasSubstr;
using testing_io::TempFolder;

// A 4 x 5 organized scan, every cell a return; cells of the middle row taken from stations 1 and 3, the last
// cell synthesized, one cell without a return.
Scan ScanWithFromStation() {
  Scan scan = MakeScan(4, 5, /*with_color=*/true);
  scan.grid = UniformGrid(4, 5, -0.2, 0.2, -0.1, 0.1);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.synthesized = cv::Mat::zeros(4, 5, CV_8U);
  scan.from_station = cv::Mat::zeros(4, 5, CV_8U);
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 5; ++col) {
      if (row == 0 && col == 0) continue;
      const float range = 3.0f + 0.1f * (row * 5 + col);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
      scan.range.at<float>(row, col) = range;
      scan.intensity.at<float>(row, col) = 0.25f;
    }
  }
  scan.from_station.at<uint8_t>(2, 1) = 1;
  scan.from_station.at<uint8_t>(2, 2) = 3;
  scan.from_station.at<uint8_t>(2, 3) = 1;
  scan.synthesized.at<uint8_t>(3, 4) = kValid;
  scan.world_from_scanner(0, 3) = 5.0;  // a station away from the origin
  return scan;
}

// The from_station values of the valid cells, in row order (LAS: the points in file order).
std::vector<int> ValuesOfValidCells(const Scan& scan) {
  std::vector<int> values;
  for (int row = 0; row < scan.rows; ++row)
    for (int col = 0; col < scan.cols; ++col)
      if (scan.valid.at<uint8_t>(row, col)) values.push_back(scan.from_station.at<uint8_t>(row, col));
  return values;
}

class FromStationRoundTrip : public testing::TestWithParam<const char*> {};

TEST_P(FromStationRoundTrip, KeepsTheChannel) {
  TempFolder folder;
  const std::string path = folder.File(std::string("filled.") + GetParam());
  const Scan scan = ScanWithFromStation();
  WriteScanFile(path, {scan});
  const ScanFile file = ReadScanFile(path);
  ASSERT_EQ(file.scans.size(), 1u);
  const Scan& back = file.scans[0];
  ASSERT_FALSE(back.from_station.empty()) << path;
  EXPECT_EQ(ValuesOfValidCells(back), ValuesOfValidCells(scan)) << path;
  if (back.rows == scan.rows) EXPECT_EQ(cv::norm(back.from_station, scan.from_station, cv::NORM_INF), 0.0);
  // The synthesized cell stays synthesized, the cells from stations do not become synthesized.
  ASSERT_FALSE(back.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(back.synthesized), 1);
  EXPECT_THAT(PlanScanWrite(path, {scan}, 0, 0).dropped, testing::Not(Contains(HasSubstr("from_station"))));
}

INSTANTIATE_TEST_SUITE_P(Formats, FromStationRoundTrip, testing::Values("e57", "las", "ply", "pcd"));

TEST(FromStation, ALasWithoutLidarshopsRecordKeepsItsUserData) {
  TempFolder folder;
  Scan scan = ScanWithFromStation();
  scan.from_station = cv::Mat();
  scan.attributes["user_data"] = cv::Mat(4, 5, CV_8U, cv::Scalar(9));
  WriteScanFile(folder.File("plain.las"), {scan});
  const Scan back = ReadScanFile(folder.File("plain.las")).scans[0];
  EXPECT_TRUE(back.from_station.empty());
  ASSERT_EQ(back.attributes.count("user_data"), 1u);
  EXPECT_EQ(cv::countNonZero(back.attributes.at("user_data") != 9), 0);
}

TEST(FromStation, PtxSaysItCannotHoldTheChannel) {
  TempFolder folder;
  const Scan scan = ScanWithFromStation();
  const ScanWritePlan plan = PlanScanWrite("out.ptx", {scan}, 0, 0);
  EXPECT_THAT(plan.dropped, Contains(AllOf(HasSubstr("out.ptx: 3 points filled from other stations"),
                                           HasSubstr("without the from_station channel"))));
  // A scan without such cells says nothing about it.
  Scan none = scan;
  none.from_station = cv::Mat::zeros(4, 5, CV_8U);
  EXPECT_THAT(PlanScanWrite("out.ptx", {none}, 0, 0).dropped,
              testing::Not(Contains(HasSubstr("from_station"))));
  // The points themselves are written.
  WriteScanFile(folder.File("out.ptx"), {scan});
  EXPECT_EQ(ReadScanFile(folder.File("out.ptx")).scans[0].CountValid(), scan.CountValid());
}

}  // namespace
}  // namespace lidarshop
