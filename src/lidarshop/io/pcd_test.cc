#include "lidarshop/io/pcd.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::ReadText;
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

TEST(PcdTest, CurvatureFieldRoundTrips) {
  TempFolder folder;
  Scan scan = ReadPcd(LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd");
  scan.curvature = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(NAN));
  for (int row = 0; row < scan.rows; row += 7) {
    for (int col = 0; col < scan.cols; col += 3)
      scan.curvature.at<float>(row, col) = 1e-4f * (row % 100 + col);
  }
  WritePcd(folder.File("curvature.pcd"), scan);
  EXPECT_THAT(ReadText(folder.File("curvature.pcd")).substr(0, 400), testing::HasSubstr(" curvature"));
  const Scan back = ReadPcd(folder.File("curvature.pcd"));
  ASSERT_EQ(back.curvature.type(), CV_32F);
  int64_t known = 0;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const float want = scan.valid.at<uint8_t>(row, col) ? scan.curvature.at<float>(row, col) : NAN;
      const float got = back.curvature.at<float>(row, col);
      if (std::isnan(want)) {
        ASSERT_TRUE(std::isnan(got)) << row << " " << col;
      } else {
        ASSERT_EQ(got, want) << row << " " << col;
        ++known;
      }
    }
  }
  EXPECT_GT(known, 1000);
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

// A 3 x 4 scan with returns, normals and colour in a pose turned 30° about z, lifted 1.5 m and moved by
// `offset` metres.
Scan PosedScan(const Eigen::Vector3d& offset) {
  Scan scan = MakeScan(3, 4, /*with_color=*/true);
  scan.grid = UniformGrid(3, 4, -0.3, 0.3, -0.2, 0.1);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.normal = cv::Mat(3, 4, CV_32FC3, cv::Scalar::all(0));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (r == 1 && c == 2) continue;  // one cell without a return
      const float range = 5.0f + 0.3f * c + 0.1f * r;
      scan.valid.at<uint8_t>(r, c) = kValid;
      scan.range.at<float>(r, c) = range;
      scan.point.at<cv::Vec3f>(r, c) = scan.direction.at<cv::Vec3f>(r, c) * range;
      scan.normal.at<cv::Vec3f>(r, c) = cv::Vec3f(0, -1, 0);
      scan.color.at<cv::Vec3b>(r, c) = cv::Vec3b(10 * r, 20 * c, 7);
    }
  }
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.topRightCorner<3, 1>() = offset + Eigen::Vector3d(0, 0, 1.5);
  scan.world_from_scanner = pose;
  return scan;
}

// The file without lidarshop's comments: what a tool that ignores VIEWPOINT and comments sees.
std::string WithoutComments(const std::string& bytes) {
  std::string out;
  size_t start = 0;
  while (start < bytes.size()) {
    const size_t end = bytes.find('\n', start);
    const std::string line = bytes.substr(start, end - start + 1);
    if (line.rfind("# frame", 0) != 0 && line.rfind("# lidarshop_scan", 0) != 0) out += line;
    if (line.rfind("DATA", 0) == 0) return out + bytes.substr(end + 1);
    start = end + 1;
  }
  return out;
}

TEST(PcdTest, WritesWorldCoordinatesAndReadsTheScanBack) {
  TempFolder folder;
  const Scan scan = PosedScan(Eigen::Vector3d(12, -3, 0));
  WritePcd(folder.File("posed.pcd"), scan);
  const std::string bytes = testing_io::ReadText(folder.File("posed.pcd"));
  const std::string header = bytes.substr(0, bytes.find("DATA binary"));
  EXPECT_THAT(header, ::testing::HasSubstr("\n# frame world\n"));
  EXPECT_THAT(header, ::testing::HasSubstr("\n# lidarshop_scan world_from_scanner "));
  EXPECT_THAT(header, ::testing::HasSubstr("\nVIEWPOINT 0 0 0 1 0 0 0\n"));
  EXPECT_THAT(header, ::testing::HasSubstr("\nWIDTH 4\nHEIGHT 3\n"));

  // Round trip: grid, scanner-frame points, normals and the pose come back.
  const Scan back = ReadPcd(folder.File("posed.pcd"));
  ASSERT_EQ(back.rows, 3);
  ASSERT_EQ(back.cols, 4);
  EXPECT_TRUE(back.world_from_scanner.isApprox(scan.world_from_scanner, 1e-15));
  EXPECT_EQ(cv::norm(back.valid, scan.valid, cv::NORM_INF), 0.0);
  EXPECT_LT(cv::norm(back.point, scan.point, cv::NORM_INF), 1e-5);
  EXPECT_LT(cv::norm(back.normal, scan.normal, cv::NORM_INF), 1e-6);
  EXPECT_EQ(cv::norm(back.color, scan.color, cv::NORM_INF), 0.0);
  EXPECT_LT(cv::norm(back.direction, scan.direction, cv::NORM_INF), 1e-5);

  // The coordinates in the file are the world's: read without the comments (as Open3D does, ignoring
  // VIEWPOINT) the world points are the scan's.
  const Scan foreign = ParsePcd(WithoutComments(bytes), "foreign.pcd");
  const PointCloud expected = ToPointCloud(scan, /*world=*/true);
  const PointCloud seen = ToPointCloud(foreign, /*world=*/true);
  ASSERT_EQ(seen.size(), expected.size());
  for (size_t i = 0; i < seen.size(); ++i) {
    EXPECT_LT((seen.points[i] - expected.points[i]).norm(), 1e-5f) << i;
  }
  EXPECT_GT(seen.points[0].z(), 1.5);  // world z of the top row: the scanner stands 1.5 m up
}

TEST(PcdTest, FarScansKeepMillimetresInDoubles) {
  TempFolder folder;
  const Scan scan = PosedScan(Eigen::Vector3d(500000, 4000000, 100));  // UTM-like coordinates
  WritePcd(folder.File("far.pcd"), scan);
  EXPECT_THAT(testing_io::ReadText(folder.File("far.pcd")), ::testing::HasSubstr("\nSIZE 8 8 8 "));
  const Scan back = ReadPcd(folder.File("far.pcd"));
  EXPECT_TRUE(back.world_from_scanner.isApprox(scan.world_from_scanner, 1e-15));
  EXPECT_LT(cv::norm(back.point, scan.point, cv::NORM_INF), 1e-5);
}

TEST(PcdTest, ABadPoseCommentIsRefused) {
  const std::string body =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n";
  EXPECT_THAT(testing_io::InputErrorOf([&] {
                ParsePcd("# lidarshop_scan world_from_scanner 1 0 0 0 0 1 0 0 0 0 1 0\n" + body, "short.pcd");
              }),
              ::testing::HasSubstr("lidarshop_scan world_from_scanner"));
  EXPECT_THAT(testing_io::InputErrorOf([&] {
                ParsePcd("# lidarshop_scan world_from_scanner 2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1\n" + body,
                         "scaled.pcd");
              }),
              ::testing::HasSubstr("scaled"));
  // A pose that is a rotation and a translation is taken: the point comes back in the scanner frame.
  const Scan scan = ParsePcd(
      "# lidarshop_scan world_from_scanner 1 0 0 10 0 1 0 0 0 0 1 1.5 0 0 0 1\n" + body, "posed.pcd");
  EXPECT_EQ(scan.point.at<cv::Vec3f>(0, 0), cv::Vec3f(-9, 2, 1.5f));
}

TEST(PcdTest, SeveralScansAreRefused) {
  TempFolder folder;
  const Scan scan = MakeScan(2, 2);
  EXPECT_THROW(WriteScanFile(folder.File("two.pcd"), {scan, scan}), InputError);
}

}  // namespace
}  // namespace lidarshop
