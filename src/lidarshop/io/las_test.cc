// LAS writing: round trips of synthetic scans through the writer and the reader (0.1 mm, colour, intensity,
// labels, synthesized), header fields, label clamping, several scans, writer errors. Reading files written by
// hand: las_reader_test.cc.
#include "lidarshop/io/las.h"

#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing_io::InputErrorOf;
using testing_io::TempFolder;

// ---- Round trips through the writer ----

Scan SyntheticScan() {
  test_scenes::GroundAndBoxOptions options;
  options.rows = 50;
  options.columns = 80;
  options.los_noise_sigma = 0.002;
  Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(options));
  // A pose far from the origin (UTM-like) and turned, so that the world frame matters.
  scan.world_from_scanner.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  scan.world_from_scanner.topRightCorner<3, 1>() = Eigen::Vector3d(512345.678, 5412345.432, 312.5);
  scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  scan.synthesized(cv::Rect(10, 30, 20, 5)).setTo(kValid);
  return scan;
}

void ExpectSamePoints(const Scan& original, const Scan& back, bool color, bool labels,
                      double intensity_step) {
  ASSERT_EQ(back.rows, 1);
  ASSERT_EQ(back.cols, original.CountValid());
  EXPECT_EQ(back.CountValid(), back.cols);
  ASSERT_EQ(back.has_color(), color);
  ASSERT_EQ(!back.label.empty(), labels);
  int i = 0;
  double worst = 0;
  for (int row = 0; row < original.rows; ++row) {
    for (int col = 0; col < original.cols; ++col) {
      if (!original.valid.at<uint8_t>(row, col)) continue;
      worst = std::max(
          worst, (WorldPointOfCell(original, row, col) - WorldPointOfCell(back, 0, i)).cwiseAbs().maxCoeff());
      EXPECT_NEAR(back.intensity.at<float>(0, i), original.intensity.at<float>(row, col), intensity_step)
          << i;
      if (color) {
        EXPECT_EQ(back.color.at<cv::Vec3b>(0, i), original.color.at<cv::Vec3b>(row, col)) << i;
      }
      if (labels) {
        EXPECT_EQ(back.label.at<int32_t>(0, i), original.label.at<int32_t>(row, col)) << i;
      }
      const bool synthesized = original.synthesized.at<uint8_t>(row, col) != 0;
      EXPECT_EQ(!back.synthesized.empty() && back.synthesized.at<uint8_t>(0, i) != 0, synthesized) << i;
      ++i;
    }
  }
  EXPECT_LE(worst, 1e-4) << "metres";  // 0.1 mm
}

TEST(LasTest, SyntheticScanRoundTripsToATenthOfAMillimetre) {
  TempFolder folder;
  const Scan scan = SyntheticScan();
  ASSERT_TRUE(scan.has_color());
  ASSERT_FALSE(scan.label.empty());
  ASSERT_GT(scan.CountValid(), 1000);
  const std::string path = folder.File("scan.las");
  WriteScanFile(path, {scan});
  const std::string bytes = testing_io::ReadText(path);
  EXPECT_EQ(bytes[104], 7);  // colour: format 7
  EXPECT_EQ(bytes.size(), 375u + 36u * scan.CountValid());
  ExpectSamePoints(scan, ReadScanFile(path).scans[0], /*color=*/true, /*labels=*/true, 0.6 / 65535);
}

TEST(LasTest, EveryWrittenFormatRoundTrips) {
  TempFolder folder;
  const Scan scan = SyntheticScan();
  for (const auto& [minor, format] : std::vector<std::pair<int, int>>{
           {2, 0}, {2, 1}, {2, 2}, {2, 3}, {4, 0}, {4, 3}, {4, 6}, {4, 7}, {4, 8}}) {
    SCOPED_TRACE(fmt::format("LAS 1.{} format {}", minor, format));
    const std::string path = folder.File("scan.las");
    WriteLas(path, {scan}, {.minor_version = minor, .point_format = format});
    const std::string bytes = testing_io::ReadText(path);
    EXPECT_EQ(bytes[25], minor);
    EXPECT_EQ(bytes[104], format);
    const bool color = format == 2 || format == 3 || format >= 7;
    ExpectSamePoints(scan, ReadScanFile(path).scans[0], color, /*labels=*/true, 0.6 / 65535);
  }
}

TEST(LasTest, HeaderFields) {
  const Scan scan = SyntheticScan();
  const std::string bytes = EncodeLas({scan}, {}, "x.las");
  auto load_double = [&](size_t at) {
    double v;
    std::memcpy(&v, bytes.data() + at, 8);
    return v;
  };
  uint16_t header_size, encoding;
  uint32_t legacy_count;
  uint64_t count;
  std::memcpy(&header_size, bytes.data() + 94, 2);
  std::memcpy(&encoding, bytes.data() + 6, 2);
  std::memcpy(&legacy_count, bytes.data() + 107, 4);
  std::memcpy(&count, bytes.data() + 247, 8);
  EXPECT_EQ(header_size, 375);
  EXPECT_EQ(encoding, 16);      // WKT bit, required with formats 6-10
  EXPECT_EQ(legacy_count, 0u);  // formats 6-10
  EXPECT_EQ(count, static_cast<uint64_t>(scan.CountValid()));
  EXPECT_EQ(load_double(131), 1e-4);
  // Offsets: the floor of the minimum; bounds: max x, min x, max y, ...
  double low[3] = {1e300, 1e300, 1e300};
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      const Eigen::Vector3d p = WorldPointOfCell(scan, row, col);
      for (int axis = 0; axis < 3; ++axis) low[axis] = std::min(low[axis], p[axis]);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(load_double(155 + 8 * axis), std::floor(low[axis]));
    EXPECT_NEAR(load_double(179 + 16 * axis + 8), low[axis], 5e-5);
  }

  const std::string v12 = EncodeLas({scan}, {.minor_version = 2}, "x.las");
  std::memcpy(&header_size, v12.data() + 94, 2);
  std::memcpy(&legacy_count, v12.data() + 107, 4);
  EXPECT_EQ(header_size, 227);
  EXPECT_EQ(v12[104], 2);  // colour, LAS 1.2
  EXPECT_EQ(legacy_count, static_cast<uint32_t>(scan.CountValid()));
}

TEST(LasTest, LabelsAreClampedToTheClassRange) {
  Scan scan = MakeScan(1, 4);
  scan.label = cv::Mat(1, 4, CV_32S, cv::Scalar(kNoLabel));
  const int32_t labels[] = {40, 300, kNoLabel, 3};
  for (int i = 0; i < 4; ++i) {
    scan.valid.at<uint8_t>(0, i) = kValid;
    scan.point.at<cv::Vec3f>(0, i) = cv::Vec3f(1.0f + i, 2, 0);
    scan.label.at<int32_t>(0, i) = labels[i];
  }
  TempFolder folder;
  const std::string path = folder.File("labels.las");
  WriteLas(path, {scan}, {.point_format = 1});  // 5-bit classes
  Scan back = ReadScanFile(path).scans[0];
  EXPECT_EQ(back.label.at<int32_t>(0, 0), 31);
  EXPECT_EQ(back.label.at<int32_t>(0, 1), 31);
  EXPECT_EQ(back.label.at<int32_t>(0, 2), 0);
  EXPECT_EQ(back.label.at<int32_t>(0, 3), 3);
  WriteLas(path, {scan}, {.point_format = 6});  // 8-bit classes
  back = ReadScanFile(path).scans[0];
  EXPECT_EQ(back.label.at<int32_t>(0, 0), 40);
  EXPECT_EQ(back.label.at<int32_t>(0, 1), 255);
}

TEST(LasTest, SeveralScansAreOneCloud) {
  TempFolder folder;
  const Scan a = SyntheticScan();
  Scan b = Clone(a);
  b.world_from_scanner(0, 3) += 20;
  const std::string path = folder.File("two.las");
  WriteScanFile(path, {a, b});
  const Scan back = ReadScanFile(path).scans[0];
  ASSERT_EQ(back.cols, a.CountValid() + b.CountValid());
  const std::string bytes = testing_io::ReadText(path);
  uint16_t source_first, source_last;
  std::memcpy(&source_first, bytes.data() + 375 + 20, 2);
  std::memcpy(&source_last, bytes.data() + bytes.size() - 36 + 20, 2);
  EXPECT_EQ(source_first, 0);  // point source ID = scan index
  EXPECT_EQ(source_last, 1);
}

TEST(LasTest, ALayerBehindIsOneCloudWithTheSyntheticFlag) {
  TempFolder folder;
  Scan front = SyntheticScan();
  front.synthesized.release();
  Scan behind = Clone(front);
  behind.valid.setTo(0);
  behind.valid(cv::Rect(5, 10, 30, 8)).setTo(kValid);
  const std::string path = folder.File("layers.las");
  WriteScanWithLayer(path, front, behind);
  const Scan back = ReadScanFile(path).scans[0];
  ASSERT_EQ(back.cols, front.CountValid() + behind.CountValid());
  ASSERT_FALSE(back.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(back.synthesized), behind.CountValid());
  EXPECT_EQ(cv::countNonZero(back.synthesized(cv::Rect(0, 0, static_cast<int>(front.CountValid()), 1))), 0);
  EXPECT_THAT(InputErrorOf([&] { WriteScanWithLayer(folder.File("layers.xyz"), front, behind); }),
              HasSubstr("cannot mark"));
}

TEST(LasTest, WriterErrors) {
  TempFolder folder;
  Scan scan = SyntheticScan();
  scan.color.release();
  EXPECT_THAT(InputErrorOf([&] { WriteLas(folder.File("c.las"), {scan}, {.point_format = 7}); }),
              AllOf(HasSubstr("c.las"), HasSubstr("point format 7 stores colour"), HasSubstr("choose 6")));
  EXPECT_THROW(WriteLas(folder.File("c.las"), {scan}, {.minor_version = 2, .point_format = 6}), OptionsError);
  EXPECT_THROW(WriteLas(folder.File("c.las"), {scan}, {.minor_version = 3}), OptionsError);
  EXPECT_THROW(WriteLas(folder.File("c.las"), {scan}, {.point_format = 4}), OptionsError);
  EXPECT_THROW(WriteLas(folder.File("c.las"), {scan}, {.coordinate_scale_m = 0}), OptionsError);
  // 1 km at 1 nm steps does not fit int32.
  EXPECT_THAT(InputErrorOf([&] { WriteLas(folder.File("c.las"), {scan}, {.coordinate_scale_m = 1e-9}); }),
              AllOf(HasSubstr("c.las"), HasSubstr("coordinate_scale_m >=")));
  EXPECT_THAT(InputErrorOf([&] { WriteLas(folder.File("c.las"), {MakeScan(2, 2)}); }),
              HasSubstr("no point with a return"));
  EXPECT_FALSE(std::filesystem::exists(folder.File("c.las")));
}

}  // namespace
}  // namespace lidarshop
