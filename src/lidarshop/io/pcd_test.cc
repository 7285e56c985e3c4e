#include "lidarshop/io/pcd.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::TempFolder;

TEST(PcdTest, ReadsTheSharedBinaryCompressedCloudAsAScan) {
  const ScanFile file = ReadScanFile(LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd");
  EXPECT_EQ(file.format, "pcd");
  ASSERT_EQ(file.scans.size(), 1u);
  const Scan& scan = file.scans[0];
  EXPECT_EQ(scan.rows, 480);
  EXPECT_EQ(scan.cols, 640);
  ASSERT_TRUE(scan.has_color());
  const int64_t valid = scan.CountValid();
  EXPECT_GT(valid, 100000);  // stereo: holes where matching failed
  EXPECT_LT(valid, 480 * 640);
  // The colour is not constant (a textured table).
  cv::Scalar mean, stddev;
  cv::meanStdDev(scan.color, mean, stddev, scan.valid);
  EXPECT_GT(stddev[0], 10.0);
  // In the scanner frame the scene is in front (y > 0); the top image row looks higher than the bottom one.
  ASSERT_TRUE(scan.grid.fitted);
  EXPECT_GT(scan.grid.elevation_rad.front(), scan.grid.elevation_rad.back());
  EXPECT_LT(scan.grid.azimuth_rad.front(), scan.grid.azimuth_rad.back());
  EXPECT_LT(scan.grid.rms_residual_rad, 0.01);
  cv::Scalar mean_point = cv::mean(scan.point, scan.valid);
  EXPECT_GT(mean_point[1], 0.3);
}

TEST(PcdTest, RoundTripKeepsTheScan) {
  TempFolder folder;
  const Scan scan = ReadPcd(LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd");
  WritePcd(folder.File("copy.pcd"), scan);
  const Scan back = ReadPcd(folder.File("copy.pcd"));
  EXPECT_EQ(back.rows, scan.rows);
  EXPECT_EQ(back.cols, scan.cols);
  EXPECT_EQ(cv::norm(back.valid, scan.valid, cv::NORM_INF), 0.0);
  EXPECT_LT(cv::norm(back.point, scan.point, cv::NORM_INF), 1e-6);
  EXPECT_EQ(cv::norm(back.color, scan.color, cv::NORM_INF), 0.0);
  EXPECT_TRUE(back.world_from_scanner.isApprox(scan.world_from_scanner, 1e-9));
}

TEST(PcdTest, AFileWithoutIntensityHasNoIntensityChannelAndWritesNone) {
  // The shared cloud's fields are x y z rgb: no intensity may be invented on reading or writing.
  TempFolder folder;
  const Scan scan = ReadPcd(LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd");
  EXPECT_FALSE(scan.has_intensity());
  EXPECT_THAT(ChannelNames(scan), testing::Not(testing::Contains("intensity")));
  EXPECT_THAT(ChannelNames(scan), testing::Contains("rgb"));
  WritePcd(folder.File("copy.pcd"), scan);
  const std::string written = testing_io::ReadText(folder.File("copy.pcd"));
  const std::string fields = written.substr(
      written.find("FIELDS"), written.find('\n', written.find("FIELDS")) - written.find("FIELDS"));
  EXPECT_EQ(fields, "FIELDS x y z rgb");
  EXPECT_FALSE(ReadPcd(folder.File("copy.pcd")).has_intensity());
  // A scan with intensity keeps it.
  Scan with = scan;
  with.intensity = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(0.25));
  WritePcd(folder.File("with.pcd"), with);
  const Scan back = ReadPcd(folder.File("with.pcd"));
  ASSERT_TRUE(back.has_intensity());
  EXPECT_FLOAT_EQ(back.intensity.at<float>(240, 320), back.valid.at<uint8_t>(240, 320) ? 0.25f : 0.5f);
}

TEST(PcdTest, ReadsAscii) {
  const std::string text =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\n"
      "HEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n"
      "-0.1 -0.1 1 0.5\nnan nan nan 0\n-0.1 0.1 1 0.25\n0.1 0.1 1 1\n";
  const Scan scan = ParsePcd(text, "mem.pcd");
  EXPECT_EQ(scan.CountValid(), 3);
  EXPECT_EQ(scan.valid.at<uint8_t>(0, 1), 0);
  // Optical frame (x right, y down, z forward) to scanner frame (x right, y forward, z up).
  EXPECT_EQ(scan.point.at<cv::Vec3f>(0, 0), cv::Vec3f(-0.1f, 1, 0.1f));
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(1, 0), 0.25f);
  // World coordinates are the file's.
  const PointCloud world = ToPointCloud(scan, /*world=*/true);
  EXPECT_TRUE(world.points[0].isApprox(Eigen::Vector3f(-0.1f, -0.1f, 1)));
}

TEST(PcdTest, SeveralScansAreRefused) {
  TempFolder folder;
  const Scan scan = MakeScan(2, 2);
  EXPECT_THROW(WriteScanFile(folder.File("two.pcd"), {scan, scan}), InputError);
}

}  // namespace
}  // namespace lidarshop
