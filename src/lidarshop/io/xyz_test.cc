// XYZ and PTS: round trips of a synthetic scan, files written by hand, and the errors of malformed lines.
#include "lidarshop/io/xyz.h"

#include <fmt/format.h>
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
using testing_io::TempFolder;
using testing_io::WriteText;

Scan SyntheticXyzScan() {
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
  const Scan scan = SyntheticXyzScan();
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
    return testing_io::ScanError(path);
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
  // PTS: a line that is neither a count (one whole number) nor a point of the first point line's columns.
  EXPECT_THAT(error_for(pts, "-3\n1 2 3\n"), AllOf(HasSubstr(pts), HasSubstr("line 1"),
                                                   HasSubstr("field 'columns'"), HasSubstr("1 numbers")));
  EXPECT_THAT(error_for(pts, "2\n1 2 3\n4 5\n"),
              AllOf(HasSubstr("line 3"), HasSubstr("field 'z'"), HasSubstr("missing")));
  EXPECT_THAT(error_for(pts, "2\n1 2 3\n4.5\n"),
              AllOf(HasSubstr("line 3"), HasSubstr("field 'y'"), HasSubstr("missing")));
  EXPECT_THAT(error_for(pts, "99999999999999999999999\n1 2 3\n"),
              AllOf(HasSubstr("line 1"), HasSubstr("field 'point count'"), HasSubstr("out of range")));
}

// A PTS count line that is missing or wrong: every point line is read, a warning names the count.
TEST(XyzTest, PtsCountMissingOrWrongIsReadWithAWarning) {
  TempFolder folder;
  const std::string path = folder.File("count.pts");
  struct Case {
    const char* text;
    int points;
    const char* warning;  // "" = none
  };
  const Case cases[] = {
      {"2\n1 2 3\n4 5 6\n", 2, ""},
      {"1 2 3\n4 5 6\n", 2, "line 1: no point count line"},
      {"5\n1 2 3\n4 5 6\n", 2, "line 1: the point count says 5 points, 2 follow it"},
      {"1\n1 2 3\n4 5 6\n7 8 9\n", 3, "line 1: the point count says 1 points, 3 follow it"},
      {"1000000000\n1 2 3\n", 1, "says 1000000000 points, 1 follow"},
      // Two blocks (one per scan), the second's count wrong.
      {"1\n1 2 3\n3\n4 5 6\n7 8 9\n", 3, "line 3: the point count says 3 points, 2 follow it"},
  };
  for (const Case& c : cases) {
    WriteText(path, c.text);
    const ScanFile file = ReadScanFile(path);
    ASSERT_EQ(file.scans.size(), 1u) << c.text;
    EXPECT_EQ(file.scans[0].CountValid(), c.points) << c.text;
    EXPECT_NEAR(WorldPointOfCell(file.scans[0], 0, c.points - 1).z(), 3.0 * c.points, 1e-6) << c.text;
    if (c.warning[0] == '\0') {
      EXPECT_TRUE(file.warnings.empty()) << c.text;
    } else {
      ASSERT_EQ(file.warnings.size(), 1u) << c.text;
      EXPECT_THAT(file.warnings[0], AllOf(StartsWith(path), HasSubstr(c.warning))) << c.text;
    }
  }
}

// In a point list the origin is a point like any other (no-return is an organized-grid convention).
TEST(XyzTest, APointAtTheOriginIsKept) {
  const Scan scan = ParsePointList("0 0 0\n1 2 3\n0 0 -0.0009765625\n", "origin.xyz", PointListKind::kXyz);
  ASSERT_EQ(scan.cols, 3);
  EXPECT_EQ(scan.CountValid(), 3);
  EXPECT_EQ(WorldPointOfCell(scan, 0, 0), Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(WorldPointOfCell(scan, 0, 1), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(WorldPointOfCell(scan, 0, 2), Eigen::Vector3d(0, 0, -0.0009765625));
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(scan.range.at<float>(0, i), 0.0f) << i;  // every point has a ray from the scan's origin
    EXPECT_NEAR(cv::norm(scan.direction.at<cv::Vec3f>(0, i)), 1.0, 1e-6) << i;
  }
}

// 5,000 km from the origin, the file's 0.1 mm come back.
TEST(XyzTest, FarCoordinatesKeepATenthOfAMillimetre) {
  const Eigen::Vector3d points[] = {{5000000.1234, -5000000.5678, 1234.0001},
                                    {5000123.4567, -4999876.5432, 1301.2345},
                                    {4999950.0001, -5000050.9999, 1199.9999}};
  std::string text = "3\n";
  for (const Eigen::Vector3d& p : points) text += fmt::format("{:.4f} {:.4f} {:.4f}\n", p.x(), p.y(), p.z());
  for (PointListKind kind : {PointListKind::kXyz, PointListKind::kPts}) {
    const Scan scan = ParsePointList(kind == PointListKind::kPts ? text : text.substr(2), "far", kind);
    ASSERT_EQ(scan.CountValid(), 3);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT((WorldPointOfCell(scan, 0, i) - points[i]).cwiseAbs().maxCoeff(), 1e-5) << i;
    }
  }
}

// PDAL's PTS and XYZ test files; expected values read from the text files.
TEST(XyzTest, ReadsTheInteropFiles) {
  struct Case {
    const char* file;
    int points;
    Eigen::Vector3d first, last;
    bool color, intensity;
  };
  const Case cases[] = {
      {"pts/autzen.pts",
       10,
       {636110.300003, 849345.050003, 512.139999},
       {636125.879990, 848971.060013, 428.050003},
       true,
       true},
      // Its count line says 8, 9 point lines follow: all are read, with a warning.
      {"pts/bunny_8.pts", 9, {-0.037829, 0.12794, 0.004474}, {-0.025508, 0.112568, 0.036676}, false, false},
      {"pts/site_56_8.pts",
       8,
       {6691.797611, 17.347517, 1203.033447},
       {6728.512429, 35.903329, -14.709473},
       false,
       true},
      {"pts/test.pts", 19, {3.980972, -2.006119, -0.010086}, {-19.501053, -24.533554, -1.533951}, true, true},
      {"xyz/data.xyz", 400, {440750, 3751290, 107}, {441890, 3750150, 107}, false, false},
  };
  for (const Case& c : cases) {
    const ScanFile file = ReadScanFile(std::string(LIDARSHOP_SHARED_DATA_DIR "/interop/") + c.file);
    ASSERT_EQ(file.scans.size(), 1u) << c.file;
    const Scan& scan = file.scans[0];
    if (std::string(c.file) == "pts/bunny_8.pts") {
      ASSERT_EQ(file.warnings.size(), 1u);
      EXPECT_THAT(file.warnings[0], HasSubstr("line 1: the point count says 8 points, 9 follow it"));
    } else {
      EXPECT_TRUE(file.warnings.empty()) << c.file;
    }
    EXPECT_EQ(scan.cols, c.points) << c.file;
    EXPECT_EQ(scan.CountValid(), c.points) << c.file;
    EXPECT_EQ(scan.has_color(), c.color) << c.file;
    EXPECT_EQ(scan.has_intensity(), c.intensity) << c.file;
    EXPECT_LT((WorldPointOfCell(scan, 0, 0) - c.first).cwiseAbs().maxCoeff(), 1e-5) << c.file;
    EXPECT_LT((WorldPointOfCell(scan, 0, c.points - 1) - c.last).cwiseAbs().maxCoeff(), 1e-5) << c.file;
  }
}

// A point a hundredth of a millimetre from the origin the reader picks (the fuzzer's find: Eigen's fuzzy
// isZero took it for the origin and a check aborted): read, with its coordinates.
TEST(XyzTest, APointNextToTheCloudOriginIsRead) {
  std::vector<std::string> warnings;
  const Scan scan =
      ParsePointList("30\n0.00001000 05.0 0100000\n", "near.pts", PointListKind::kPts, &warnings);
  ASSERT_EQ(scan.CountValid(), 1);
  EXPECT_LT((WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(1e-5, 5, 100000)).norm(), 1e-6);
}

// XYZ and PTS cannot mark synthesized points: they are written, and the write plan says how many went
// unmarked (what `convert` prints), as for every other thing a target cannot hold.
TEST(XyzTest, SynthesizedPointsAreWrittenAndThePlanSaysTheyAreUnmarked) {
  TempFolder folder;
  Scan scan = SyntheticXyzScan();
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
