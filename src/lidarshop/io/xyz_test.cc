// XYZ and PTS: round trips of a synthetic scan, files written by hand, and the errors of malformed lines.
#include "lidarshop/io/xyz.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing::StartsWith;
using testing_io::InputErrorOf;
using testing_io::TempFolder;
using testing_io::WriteText;

Scan SyntheticScan() {
  test_scenes::GroundAndBoxOptions options;
  options.rows = 40;
  options.columns = 60;
  Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(options));
  scan.world_from_scanner.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  scan.world_from_scanner.topRightCorner<3, 1>() = Eigen::Vector3d(512345.678, 5412345.432, 312.5);
  return scan;
}

// Points of `back` (1 x N) against the valid cells of `original`, in order; returns the largest coordinate
// difference in metres.
double CompareClouds(const Scan& original, const Scan& back, double intensity_step) {
  EXPECT_EQ(back.rows, 1);
  EXPECT_EQ(back.cols, original.CountValid());
  EXPECT_EQ(back.CountValid(), back.cols);
  EXPECT_EQ(back.has_color(), original.has_color());
  double worst = 0;
  int i = 0;
  for (int row = 0; row < original.rows; ++row) {
    for (int col = 0; col < original.cols; ++col) {
      if (!original.valid.at<uint8_t>(row, col) || i >= back.cols) continue;
      worst = std::max(
          worst, (WorldPointOfCell(original, row, col) - WorldPointOfCell(back, 0, i)).cwiseAbs().maxCoeff());
      EXPECT_NEAR(back.intensity.at<float>(0, i), original.intensity.at<float>(row, col), intensity_step)
          << i;
      if (original.has_color()) {
        EXPECT_EQ(back.color.at<cv::Vec3b>(0, i), original.color.at<cv::Vec3b>(row, col));
      }
      ++i;
    }
  }
  return worst;
}

TEST(XyzTest, RoundTrips) {
  TempFolder folder;
  const Scan scan = SyntheticScan();
  ASSERT_TRUE(scan.has_color());
  WriteScanFile(folder.File("scan.xyz"), {scan});
  WriteScanFile(folder.File("scan.pts"), {scan});
  EXPECT_LE(CompareClouds(scan, ReadScanFile(folder.File("scan.xyz")).scans[0], 0), 1e-4);
  EXPECT_LE(CompareClouds(scan, ReadScanFile(folder.File("scan.pts")).scans[0], 0.5 / 4095 + 1e-6), 1e-4);
  const std::string pts = testing_io::ReadText(folder.File("scan.pts"));
  EXPECT_THAT(pts, StartsWith(std::to_string(scan.CountValid()) + "\n"));
  // Without colour: 4 columns.
  Scan grey = Clone(scan);
  grey.color.release();
  WriteScanFile(folder.File("grey.xyz"), {grey});
  const Scan back = ReadScanFile(folder.File("grey.xyz")).scans[0];
  EXPECT_FALSE(back.has_color());
  EXPECT_LE(CompareClouds(grey, back, 0), 1e-4);
}

TEST(XyzTest, ColumnsAndIntensityRanges) {
  TempFolder folder;
  const std::string path = folder.File("hand.xyz");
  WriteText(path, "# a comment\n// another\n1 2 3\n\n4 5 6\r\n");
  Scan scan = ReadScanFile(path).scans[0];
  ASSERT_EQ(scan.cols, 2);
  EXPECT_FALSE(scan.has_color());
  EXPECT_FALSE(scan.has_intensity());  // no intensity column: no channel
  EXPECT_EQ(scan.point.at<cv::Vec3f>(0, 1), cv::Vec3f(4, 5, 6));

  WriteText(path, "1 2 3 0 10 20 30\n4 5 6 255 40 50 60\n7 8 9 51 0 0 0\n");  // 0-255 intensities
  scan = ReadScanFile(path).scans[0];
  ASSERT_TRUE(scan.has_color());
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 1), cv::Vec3b(40, 50, 60));
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 1), 1.0f);
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 2), 0.2f);

  WriteText(path, "1 2 3 10 20 30\n");  // 6 columns: colour, no intensity
  scan = ReadScanFile(path).scans[0];
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
  EXPECT_FALSE(scan.has_intensity());

  const std::string pts = folder.File("hand.pts");
  WriteText(pts, "2\n1 2 3 -2048\n4 5 6 2047\n1\n7 8 9 0\n");  // two blocks, Leica's intensity range
  scan = ReadScanFile(pts).scans[0];
  ASSERT_EQ(scan.cols, 3);
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 1), 1.0f);
  EXPECT_NEAR(scan.intensity.at<float>(0, 2), 0.5f, 1e-3);

  // UTM coordinates keep their tenths of millimetres (float alone would keep half metres).
  WriteText(path, "512345.1234 5412345.5678 310.0001\n512346.0001 5412344.9999 311.5\n");
  scan = ReadScanFile(path).scans[0];
  EXPECT_LT((WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(512345.1234, 5412345.5678, 310.0001)).norm(),
            2e-5);
  EXPECT_LT((WorldPointOfCell(scan, 0, 1) - Eigen::Vector3d(512346.0001, 5412344.9999, 311.5)).norm(), 2e-5);
}

TEST(XyzTest, MalformedLinesNameFileLineAndColumn) {
  TempFolder folder;
  const std::string xyz = folder.File("bad.xyz");
  const std::string pts = folder.File("bad.pts");
  auto error_for = [&](const std::string& path, const std::string& text) {
    WriteText(path, text);
    return InputErrorOf([&] { ReadScanFile(path); });
  };
  EXPECT_THAT(error_for(xyz, ""), AllOf(HasSubstr(xyz), HasSubstr("empty")));
  EXPECT_THAT(error_for(xyz, "# only a comment\n"), HasSubstr("no points"));
  EXPECT_THAT(error_for(xyz, "1 2 3 4 5\n"), AllOf(HasSubstr(xyz), HasSubstr("line 1"),
                                                   HasSubstr("field 'columns'"), HasSubstr("5 numbers")));
  EXPECT_THAT(error_for(xyz, "1 2 3\n4 5 6 7\n"),
              AllOf(HasSubstr("line 2"), HasSubstr("more than the 3 numbers")));
  EXPECT_THAT(error_for(xyz, "1 2 3 4\n4 5 6\n"), AllOf(HasSubstr("line 2"), HasSubstr("field 'intensity'")));
  EXPECT_THAT(error_for(xyz, "1 2 3\n4 abc 6\n"),
              AllOf(HasSubstr("line 2"), HasSubstr("field 'y'"), HasSubstr("'abc'")));
  EXPECT_THAT(error_for(xyz, "1 2 3 0.5 1 2 300\n"), AllOf(HasSubstr("field 'blue'"), HasSubstr("0-255")));
  EXPECT_THAT(error_for(xyz, "1 2 nan\n"), AllOf(HasSubstr("field 'z'"), HasSubstr("not a finite")));
  EXPECT_THAT(error_for(xyz, "1 2 3e30\n"), AllOf(HasSubstr("field 'z'"), HasSubstr("within")));
  EXPECT_THAT(
      error_for(pts, "1000000000\n1 2 3\n"),
      AllOf(HasSubstr(pts), HasSubstr("line 1"), HasSubstr("field 'point count'"), HasSubstr("truncated")));
  EXPECT_THAT(error_for(pts, "3\n1 2 3\n4 5 6\n"),
              AllOf(HasSubstr("line 1"), HasSubstr("3 points claimed, found 2")));
  EXPECT_THAT(error_for(pts, "-3\n1 2 3\n"), HasSubstr("not a number of points"));
  EXPECT_THAT(error_for(pts, "1 2 3\n"), AllOf(HasSubstr("line 1"), HasSubstr("after the point count")));
}

// XYZ and PTS cannot mark synthesized points: they are written, and the write plan says how many went
// unmarked (what `convert` prints), as for every other thing a target cannot hold.
TEST(XyzTest, SynthesizedPointsAreWrittenAndThePlanSaysTheyAreUnmarked) {
  TempFolder folder;
  Scan scan = SyntheticScan();
  scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  scan.synthesized(cv::Rect(0, 30, 10, 2)).setTo(kValid);
  const int64_t synthesized = cv::countNonZero(scan.synthesized & scan.valid);
  ASSERT_GT(synthesized, 0);
  for (const char* name : {"s.xyz", "s.pts"}) {
    const std::string path = folder.File(name);
    WriteScanFile(path, {scan});
    EXPECT_EQ(ReadScanFile(path).scans.at(0).CountValid(), scan.CountValid());
    const ScanWritePlan plan = PlanScanWrite(path, {scan}, 0, 0);
    EXPECT_THAT(plan.dropped,
                testing::Contains(AllOf(HasSubstr(path), HasSubstr(std::to_string(synthesized)),
                                        HasSubstr("without their flag"), HasSubstr("--drop-synthesized"))));
  }
  scan.synthesized.setTo(0);  // the channel alone, with nothing synthesized, says nothing
  EXPECT_THAT(PlanScanWrite(folder.File("s.xyz"), {scan}, 0, 0).dropped,
              testing::Not(testing::Contains(HasSubstr("synthesized"))));
}

}  // namespace
}  // namespace lidarshop
