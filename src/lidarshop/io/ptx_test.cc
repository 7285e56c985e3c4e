#include "lidarshop/io/ptx.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::TempFolder;

// A 2-column, 3-row scan; the pose translates by (1, 2, 3) and rotates 90° about z. Leica prints the
// transpose: rotation columns first, "tx ty tz 1" last.
const char kHeader[] =
    "2\n3\n"
    "1 2 3\n0 1 0\n-1 0 0\n0 0 1\n"
    "0 1 0 0\n-1 0 0 0\n0 0 1 0\n1 2 3 1\n";

std::string FourFieldScan() {
  return std::string(kHeader) +
         // column 0, bottom to top
         "-0.1 1 -0.1 0.25\n-0.1 1 0 0.5\n0 0 0 0.5\n"
         // column 1, bottom to top
         "0.1 1 -0.1 0.75\n0.1 1 0 1\n0.1 1 0.1 0.125\n";
}

TEST(PtxTest, ReadsLayoutOrientationAndPose) {
  const std::vector<Scan> scans = ParsePtx(FourFieldScan(), "test.ptx");
  ASSERT_EQ(scans.size(), 1u);
  const Scan& scan = scans[0];
  EXPECT_EQ(scan.rows, 3);
  EXPECT_EQ(scan.cols, 2);
  EXPECT_EQ(scan.CountValid(), 5);
  EXPECT_FALSE(scan.has_color());
  // PTX row r (bottom to top) is image row rows - 1 - r: the first line of column 0 is the bottom-left cell.
  EXPECT_EQ(scan.point.at<cv::Vec3f>(2, 0), cv::Vec3f(-0.1f, 1, -0.1f));
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(2, 0), 0.25f);
  // The third line of column 0 is "0 0 0": no return at the top-left cell.
  EXPECT_EQ(scan.valid.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(scan.point.at<cv::Vec3f>(0, 1), cv::Vec3f(0.1f, 1, 0.1f));
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 1), 0.125f);
  EXPECT_NEAR(scan.range.at<float>(1, 1), std::sqrt(1.01f), 1e-6);
  // world_from_scanner is the transpose of what is printed.
  Eigen::Matrix4d expected;
  expected << 0, -1, 0, 1, 1, 0, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1;
  EXPECT_TRUE(scan.world_from_scanner.isApprox(expected)) << scan.world_from_scanner;
  // Every cell has a direction, also the one without a return, pointing up-left.
  ASSERT_TRUE(scan.grid.fitted);
  // The fitted grid gives every ray: the read keeps no image of them (ray_directions.h).
  EXPECT_TRUE(HasCompleteGrid(scan));
  EXPECT_TRUE(scan.direction.empty());
  const cv::Vec3f up_left = DirectionImage(scan).at<cv::Vec3f>(0, 0);
  EXPECT_LT(up_left[0], 0);
  EXPECT_GT(up_left[2], 0);
  EXPECT_NEAR(cv::norm(up_left), 1.0, 1e-6);
}

TEST(PtxTest, WriteOfReadGivesTheSameContent) {
  const std::string text = FourFieldScan();
  const std::string written = FormatPtx(ParsePtx(text, "test.ptx"));
  EXPECT_EQ(written, text);
}

TEST(PtxTest, SevenFieldsSeveralScansAndCrlf) {
  std::string one = std::string(kHeader) +
                    "-0.1 1 -0.1 0.25 10 20 30\n-0.1 1 0 0.5 40 50 60\n0 0 0 0.5 0 0 0\n"
                    "0.1 1 -0.1 0.75 70 80 90\n0.1 1 0 1 100 110 120\n0.1 1 0.1 0.125 255 0 1\n";
  std::string two =
      "1\n2\n5 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n5 0 0 1\n"
      "0 2.5 -1 0.5 1 2 3\n0 2.5 1 0.5 4 5 6\n";
  const std::string text = one + two;
  std::string crlf;
  for (char c : text) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const std::vector<Scan> scans = ParsePtx(crlf, "test.ptx");
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_TRUE(scans[0].has_color());
  EXPECT_EQ(scans[0].color.at<cv::Vec3b>(2, 0), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(scans[0].color.at<cv::Vec3b>(0, 1), cv::Vec3b(255, 0, 1));
  EXPECT_EQ(scans[1].rows, 2);
  EXPECT_EQ(scans[1].cols, 1);
  EXPECT_DOUBLE_EQ(scans[1].world_from_scanner(0, 3), 5.0);
  EXPECT_EQ(scans[1].point.at<cv::Vec3f>(0, 0), cv::Vec3f(0, 2.5f, 1));  // top = the last line of the column
  // Written back (LF endings), the content is the same.
  EXPECT_EQ(FormatPtx(scans), text);
}

TEST(PtxTest, FileRoundTripThroughScanIo) {
  TempFolder folder;
  const std::string path = folder.File("scan.ptx");
  const std::vector<Scan> scans = ParsePtx(FourFieldScan(), "test.ptx");
  WriteScanFile(path, scans);
  const ScanFile file = ReadScanFile(path);
  EXPECT_EQ(file.format, "ptx");
  ASSERT_EQ(file.scans.size(), 1u);
  EXPECT_EQ(cv::norm(file.scans[0].point, scans[0].point, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(file.scans[0].valid, scans[0].valid, cv::NORM_INF), 0.0);
  EXPECT_EQ(testing_io::ReadText(path), FourFieldScan());
}

TEST(PtxTest, ShortestFloatsRoundTripExactly) {
  Scan scan = MakeScan(2, 2);
  // Within kScanRangeKeptM (10 km): farther points would be moved to a local origin.
  const float values[] = {1.0f / 3.0f, 9876.789f, -1e-5f, 7.0f};
  for (int i = 0; i < 4; ++i) {
    scan.valid.at<uint8_t>(i / 2, i % 2) = kValid;
    scan.point.at<cv::Vec3f>(i / 2, i % 2) = cv::Vec3f(values[i], 1.0f, -values[i]);
    scan.intensity.at<float>(i / 2, i % 2) = 0.1f * i;
  }
  scan.world_from_scanner(0, 3) = 1.0 / 7.0;
  const Scan back = ParsePtx(FormatPtx({scan}), "mem.ptx")[0];
  EXPECT_EQ(cv::norm(back.point, scan.point, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(back.intensity, scan.intensity, cv::NORM_INF), 0.0);
  EXPECT_EQ(back.world_from_scanner(0, 3), 1.0 / 7.0);
}

TEST(PtxTest, UsualMatrixLayoutIsRecognised) {
  std::string text =
      "1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
      "1 0 0 4\n0 1 0 5\n0 0 1 6\n0 0 0 1\n"
      "0 1 0 0.5\n";
  const Scan scan = ParsePtx(text, "usual.ptx")[0];
  EXPECT_TRUE((scan.world_from_scanner.topRightCorner<3, 1>() == Eigen::Vector3d(4, 5, 6)));
}

TEST(PtxTest, ErrorsNameLineAndField) {
  std::string text = FourFieldScan();
  text.replace(text.find("0.1 1 0 1"), 9, "0.1 x 0 1");
  EXPECT_THAT([&] { ParsePtx(text, "bad.ptx"); }, testing::ThrowsMessage<InputError>(testing::HasSubstr(
                                                      "bad.ptx: line 15: field 'y': not a number: 'x'")));
}

// PDAL's PTX test files; expected world coordinates computed from the text (the transform printed in Leica's
// layout applied by hand).
TEST(PtxTest, ReadsTheInteropFilesInWorldCoordinates) {
  const std::string dir = LIDARSHOP_SHARED_DATA_DIR "/interop/ptx/";
  // A transform with a scale (z doubled: det^(1/3) = 1.26): applied to the points, warned; the pose rigid.
  const ScanFile scaled = ReadScanFile(dir + "multiple-and-transform.ptx");
  ASSERT_EQ(scaled.scans.size(), 2u);
  const Scan& first = scaled.scans[0];
  EXPECT_EQ(first.CountValid(), 4);
  EXPECT_TRUE((first.world_from_scanner.topLeftCorner<3, 3>().isIdentity(1e-12)));
  // The points lie 61 km from the scanner: kept relative to a local origin (a second warning).
  // Bottom of column 0: "37012.24 49028.31 15.83" -> (600000 + 37012.24, 800000 + 49028.31, 400 + 2 * 15.83).
  EXPECT_LT(
      (WorldPointOfCell(first, 1, 0) - Eigen::Vector3d(637012.24, 849028.31, 431.66)).cwiseAbs().maxCoeff(),
      5e-5);
  ASSERT_EQ(scaled.warnings.size(), 3u);  // scan 1: the scale and the local origin; scan 2: the local origin
  EXPECT_THAT(scaled.warnings[0], testing::AllOf(testing::StartsWith(dir + "multiple-and-transform.ptx"),
                                                 testing::HasSubstr("scan 1"), testing::HasSubstr("scale"),
                                                 testing::HasSubstr("1.25992")));
  // Its second scan holds the same points with an identity transform, 1,000 km from the origin: a local
  // origin keeps the file's centimetres (floats there are 6 cm coarse; relative to the local origin, a few
  // hundred metres away, 0.03 mm).
  const Scan& second = scaled.scans[1];
  EXPECT_EQ(second.CountValid(), 4);
  EXPECT_LT(
      (WorldPointOfCell(second, 0, 0) - Eigen::Vector3d(637012.24, 849028.31, 431.66)).cwiseAbs().maxCoeff(),
      5e-5);

  const ScanFile color = ReadScanFile(dir + "1.2-with-color.ptx");
  ASSERT_EQ(color.scans.size(), 1u);
  EXPECT_EQ(color.scans[0].rows, 71);
  EXPECT_EQ(color.scans[0].cols, 15);
  EXPECT_EQ(color.scans[0].CountValid(), 15 * 71);
  // The cloud is 3.4 x 4.6 km wide: its corner points lie 2.2 km from the local origin, where a float keeps
  // 0.12 mm (the file's resolution is 1 cm).
  EXPECT_LT((WorldPointOfCell(color.scans[0], 70, 0) - Eigen::Vector3d(637012.24, 849028.31, 431.66))
                .cwiseAbs()
                .maxCoeff(),
            2e-4);
  EXPECT_EQ(color.scans[0].color.at<cv::Vec3b>(70, 0), cv::Vec3b(68, 77, 88));
  ASSERT_EQ(color.warnings.size(), 1u);
  EXPECT_THAT(color.warnings[0], testing::HasSubstr("local origin"));

  const ScanFile plain = ReadScanFile(dir + "no-color.ptx");
  EXPECT_EQ(plain.scans[0].CountValid(), 15);
  EXPECT_FALSE(plain.scans[0].has_color());
  EXPECT_LT((WorldPointOfCell(plain.scans[0], 0, 0) - Eigen::Vector3d(637012.24, 849028.31, 431.66))
                .cwiseAbs()
                .maxCoeff(),
            5e-5);

  // A rotation printed to 6 decimals and a translation: first return of column 0 (bottom to top: 4 empty
  // cells, then "-0.005630 0.645218 -0.440506"), world = transform applied by hand.
  const ScanFile complex = ReadScanFile(dir + "complex-transform.ptx");
  EXPECT_TRUE(complex.warnings.empty());
  ASSERT_EQ(complex.scans.size(), 1u);
  // The printed rotation is orthonormal to 1e-5 only: the pose is its nearest rotation (E57 can store it).
  EXPECT_TRUE(IsRigid(complex.scans[0].world_from_scanner, 1e-12));
  EXPECT_EQ(complex.scans[0].CountValid(), 4);
  EXPECT_LT((WorldPointOfCell(complex.scans[0], 1, 0) -
             Eigen::Vector3d(-3.0344073807900003, -3.173781036324, -1.823750041614))
                .cwiseAbs()
                .maxCoeff(),
            1e-6);
}

// Points 5,000 km from a scanner with an identity transform come back to 0.1 mm; a mirror is refused.
TEST(PtxTest, FarPointsKeepATenthOfAMillimetreAndMirrorsAreRefused) {
  const std::string head = "1\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  std::vector<std::string> warnings;
  const Scan scan = ParsePtx(head +
                                 "5000000.1234 -5000000.5678 1234.0001 0.5\n5000001.0001 -4999999.9999 "
                                 "1234.5 0.5\n",
                             "far.ptx", {}, &warnings)[0];
  EXPECT_LT((WorldPointOfCell(scan, 1, 0) - Eigen::Vector3d(5000000.1234, -5000000.5678, 1234.0001))
                .cwiseAbs()
                .maxCoeff(),
            1e-5);
  EXPECT_LT((WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(5000001.0001, -4999999.9999, 1234.5))
                .cwiseAbs()
                .maxCoeff(),
            1e-5);
  EXPECT_EQ(warnings.size(), 1u);
  // Written and read back: the same world points.
  const Scan back = ParsePtx(FormatPtx({scan}), "copy.ptx")[0];
  for (int row = 0; row < 2; ++row) {
    EXPECT_LT((WorldPointOfCell(back, row, 0) - WorldPointOfCell(scan, row, 0)).cwiseAbs().maxCoeff(), 1e-6);
  }
  const std::string mirror =
      "1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3 0.5\n";
  EXPECT_THAT(testing_io::InputErrorOf([&] {
                testing_io::TempFolder folder;
                testing_io::WriteText(folder.File("mirror.ptx"), mirror);
                ReadScanFile(folder.File("mirror.ptx"));
              }),
              testing::AllOf(testing::HasSubstr("mirror.ptx"), testing::HasSubstr("field 'pose'"),
                             testing::HasSubstr("mirrored")));
}

}  // namespace
}  // namespace lidarshop
