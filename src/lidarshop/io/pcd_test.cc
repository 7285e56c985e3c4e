#include "lidarshop/io/pcd.h"

#include <cmath>

#include <cstdio>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/scan/ray_directions.h"
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
  // Its rays are the fitted grid's: none held as an image (ray_directions.h).
  EXPECT_TRUE(HasCompleteGrid(scan));
  EXPECT_TRUE(scan.direction.empty());
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
      scan.point.at<cv::Vec3f>(r, c) = DirectionImage(scan).at<cv::Vec3f>(r, c) * range;
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
  // VIEWPOINT is the scan's pose (the sensor's, in PCL's optical frame): its position is the scanner's.
  EXPECT_THAT(header, ::testing::HasSubstr("\nVIEWPOINT 12 -3 1.5 "));
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
  EXPECT_LT(cv::norm(DirectionImage(back), DirectionImage(scan), cv::NORM_INF), 1e-5);

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

// An organized cloud with its sensor somewhere: the file's numbers come back as world points, the pose is the
// VIEWPOINT, the grid is in image orientation, and a written copy keeps both.
TEST(PcdTest, ViewpointIsTheSensorPoseNotAppliedToThePoints) {
  // Sensor at (10, 20, 30), turned 90° about z; points 2 m in front of it along its optical z (world -x... ).
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  Eigen::Matrix4d world_from_sensor = Eigen::Matrix4d::Identity();
  world_from_sensor.topLeftCorner<3, 3>() = turn.toRotationMatrix();
  world_from_sensor.topRightCorner<3, 1>() = Eigen::Vector3d(10, 20, 30);
  std::vector<Eigen::Vector3d> world;
  std::string data;
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      const Eigen::Vector3d in_sensor(-0.2 + 0.2 * col, -0.1 + 0.2 * row, 2.0 + 0.01 * col);
      world.push_back(world_from_sensor.topLeftCorner<3, 3>() * in_sensor + Eigen::Vector3d(10, 20, 30));
      data += fmt::format("{} {} {}\n", world.back().x(), world.back().y(), world.back().z());
    }
  }
  const std::string text = fmt::format(
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 2\n"
      "VIEWPOINT 10 20 30 {} {} {} {}\nPOINTS 6\nDATA ascii\n{}",
      turn.w(), turn.x(), turn.y(), turn.z(), data);
  const Scan scan = ParsePcd(text, "posed.pcd");
  ASSERT_EQ(scan.CountValid(), 6);
  for (int i = 0; i < 6; ++i) {
    EXPECT_LT((WorldPointOfCell(scan, i / 3, i % 3) - world[i]).cwiseAbs().maxCoeff(), 1e-6) << i;
  }
  EXPECT_TRUE((scan.world_from_scanner.topRightCorner<3, 1>().isApprox(Eigen::Vector3d(10, 20, 30))));
  // The scanner looks along the sensor's optical axis: forward (scanner y) is the sensor's z.
  const Eigen::Vector3d forward = scan.world_from_scanner.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitY();
  EXPECT_TRUE(forward.isApprox(world_from_sensor.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ(), 1e-12));
  // Image orientation: row 0 is the top (optical y down), azimuth grows to the right.
  EXPECT_GT(scan.grid.elevation_rad.front(), scan.grid.elevation_rad.back());
  EXPECT_LT(scan.grid.azimuth_rad.front(), scan.grid.azimuth_rad.back());

  // Written and read back (also without lidarshop's comments, as other tools write it): the same points and
  // pose, and VIEWPOINT as in the file.
  TempFolder folder;
  WritePcd(folder.File("copy.pcd"), scan);
  const std::string bytes = ReadText(folder.File("copy.pcd"));
  EXPECT_THAT(bytes, ::testing::HasSubstr("\nSIZE 4 4 4\n"));
  std::string viewpoint = bytes.substr(bytes.find("VIEWPOINT ") + 10);
  viewpoint = viewpoint.substr(0, viewpoint.find('\n'));
  double v[7];
  ASSERT_EQ(std::sscanf(viewpoint.c_str(), "%lf %lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3], &v[4],
                        &v[5], &v[6]),
            7);
  const double sign = v[3] * turn.w() < 0 ? -1 : 1;  // q and -q are one rotation
  EXPECT_TRUE(Eigen::Vector4d(v[3], v[4], v[5], v[6])
                  .isApprox(sign * Eigen::Vector4d(turn.w(), turn.x(), turn.y(), turn.z()), 1e-12));
  EXPECT_TRUE(Eigen::Vector3d(v[0], v[1], v[2]).isApprox(Eigen::Vector3d(10, 20, 30), 1e-12));
  for (const Scan& back :
       {ReadPcd(folder.File("copy.pcd")), ParsePcd(WithoutComments(bytes), "foreign.pcd")}) {
    EXPECT_TRUE(back.world_from_scanner.isApprox(scan.world_from_scanner, 1e-12));
    for (int i = 0; i < 6; ++i) {
      EXPECT_LT((WorldPointOfCell(back, i / 3, i % 3) - world[i]).cwiseAbs().maxCoeff(), 1e-5) << i;
    }
  }
}

// PCL's stereo cloud: VIEWPOINT "0 0 0 0 1 0 0" (half a turn about x). The file's numbers are what PCL,
// Open3D and CloudCompare show: the scene in front of the camera (z > 0), the image's top row at smaller
// y (optical y down); lidarshop used to apply the VIEWPOINT and give (x, -y, -z).
TEST(PcdTest, TheStereoCloudKeepsTheFilesCoordinates) {
  const Scan scan = ReadPcd(LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd");
  const PointCloud world = ToPointCloud(scan, /*world=*/true);
  ASSERT_GT(world.size(), 100000u);
  double mean_z = 0;
  for (const Eigen::Vector3f& p : world.points) mean_z += p.z();
  EXPECT_GT(mean_z / world.size(), 0.5);
  // The sensor is at the VIEWPOINT's position; the scene lies ahead (scanner y > 0), row 0 on top.
  EXPECT_TRUE((scan.world_from_scanner.topRightCorner<3, 1>().isZero()));
  EXPECT_GT(cv::mean(scan.point, scan.valid)[1], 0.3);
  EXPECT_GT(scan.grid.elevation_rad.front(), scan.grid.elevation_rad.back());
  double top_y = 0, bottom_y = 0;
  int top = 0, bottom = 0;
  for (int col = 0; col < scan.cols; ++col) {
    for (int row : {40, scan.rows - 40}) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      (row == 40 ? top_y : bottom_y) += WorldPointOfCell(scan, row, col).y();
      ++(row == 40 ? top : bottom);
    }
  }
  ASSERT_GT(top, 0);
  ASSERT_GT(bottom, 0);
  EXPECT_LT(top_y / top, bottom_y / bottom);
}

// PDAL's PCD test files: comma, tab and space separated ascii with upper-case FIELDS, binary with PDAL's
// fields, and a file without its header. Expected values read from the text / with Python's struct.
TEST(PcdTest, ReadsThePdalInteropFiles) {
  for (const char* name : {"utm17_space.pcd", "utm17_comma.pcd", "utm17_tab.pcd"}) {
    const ScanFile file = ReadScanFile(std::string(LIDARSHOP_SHARED_DATA_DIR "/interop/pcd/") + name);
    ASSERT_EQ(file.scans.size(), 1u) << name;
    const Scan& scan = file.scans[0];
    EXPECT_EQ(scan.rows, 1) << name;
    EXPECT_EQ(scan.CountValid(), 10) << name;
    // The text's centimetres, although SIZE says 4 (a float there is 0.5 m coarse).
    EXPECT_LT(
        (WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(289814.15, 4320978.61, 170.76)).cwiseAbs().maxCoeff(),
        1e-6)
        << name;
    EXPECT_LT(
        (WorldPointOfCell(scan, 0, 9) - Eigen::Vector3d(289818.50, 4320980.59, 170.58)).cwiseAbs().maxCoeff(),
        1e-6)
        << name;
  }
  const ScanFile autzen = ReadScanFile(LIDARSHOP_SHARED_DATA_DIR "/interop/pcd/autzen-utm.pcd");
  const Scan& scan = autzen.scans[0];
  EXPECT_EQ(scan.CountValid(), 1065);
  // 1.3 km wide: floats a few hundred metres from the local origin keep 0.03 mm.
  EXPECT_LT(
      (WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(494428.61, 4877455.58, 131.57)).cwiseAbs().maxCoeff(),
      5e-5);
  EXPECT_LT((WorldPointOfCell(scan, 0, 1064) - Eigen::Vector3d(494490.24, 4878741.67, 129.21))
                .cwiseAbs()
                .maxCoeff(),
            5e-5);
  ASSERT_TRUE(scan.has_color());  // Red Green Blue fields
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 0), cv::Vec3b(68, 77, 88));
  ASSERT_TRUE(scan.has_intensity());  // 16-bit Intensity scaled to [0, 1]
  EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 0), 143.0f / 65535.0f);

  const std::string missing = LIDARSHOP_SHARED_DATA_DIR "/interop/pcd/missingheader.pcd";
  EXPECT_THAT(testing_io::ScanError(missing),
              ::testing::AllOf(::testing::HasSubstr(missing), ::testing::HasSubstr("line 1"),
                               ::testing::HasSubstr("starts with data")));
}

// Unorganized clouds: the origin is a point, and coordinates 5,000 km out keep 0.1 mm through a read and a
// write (as F 8, with the plan saying so).
TEST(PcdTest, UnorganizedCloudsKeepTheOriginAndFarCoordinates) {
  const std::string head =
      "VERSION 0.7\nFIELDS X Y Z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";
  const Scan near = ParsePcd(head + "0 0 0\n1,2,3\nnan nan nan\n", "near.pcd");
  EXPECT_EQ(near.CountValid(), 2);
  EXPECT_EQ(WorldPointOfCell(near, 0, 0), Eigen::Vector3d(0, 0, 0));
  EXPECT_GT(near.range.at<float>(0, 0), 0.0f);

  const Eigen::Vector3d far[] = {{5000000.1234, 12.0001, -5000000.5678},
                                 {5000100.0001, 13.9999, -4999900.4321}};
  const Scan scan =
      ParsePcd(head + fmt::format("{:.4f} {:.4f} {:.4f}\n{:.4f}\t{:.4f}\t{:.4f}\nnan nan nan\n", far[0].x(),
                                  far[0].y(), far[0].z(), far[1].x(), far[1].y(), far[1].z()),
               "far.pcd");
  for (int i = 0; i < 2; ++i) EXPECT_LT((WorldPointOfCell(scan, 0, i) - far[i]).cwiseAbs().maxCoeff(), 1e-5);
  TempFolder folder;
  EXPECT_TRUE(PcdNeedsDoubleCoordinates(scan));
  WritePcd(folder.File("far.pcd"), scan);
  EXPECT_THAT(ReadText(folder.File("far.pcd")), ::testing::HasSubstr("\nSIZE 8 8 8\n"));
  // convert says so before writing.
  const ScanWritePlan plan = PlanScanWrite(folder.File("far.pcd"), {scan}, 0, 0);
  ASSERT_EQ(plan.dropped.size(), 1u);
  EXPECT_THAT(plan.dropped[0], ::testing::AllOf(::testing::StartsWith(folder.File("far.pcd")),
                                                ::testing::HasSubstr("F 8"), ::testing::HasSubstr("Open3D")));
  EXPECT_TRUE(PlanScanWrite(folder.File("near.pcd"), {near}, 0, 0).dropped.empty());
  const Scan back = ReadPcd(folder.File("far.pcd"));
  for (int i = 0; i < 2; ++i) EXPECT_LT((WorldPointOfCell(back, 0, i) - far[i]).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_FALSE(PcdNeedsDoubleCoordinates(near));
  WritePcd(folder.File("near.pcd"), near);
  EXPECT_THAT(ReadText(folder.File("near.pcd")), ::testing::HasSubstr("\nSIZE 4 4 4\n"));
}

TEST(PcdTest, SeveralScansAreRefused) {
  TempFolder folder;
  const Scan scan = MakeScan(2, 2);
  EXPECT_THROW(WriteScanFile(folder.File("two.pcd"), {scan, scan}), InputError);
}

}  // namespace
}  // namespace lidarshop
