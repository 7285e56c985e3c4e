// Second viewpoints keep the scan's up, and their camera depends on the region and the pose only.
#include "lidarshop/render/render_view.h"

#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

// The pixels of `picture` (CV_8UC3) that are not black, as points (x right, y down).
std::vector<cv::Point> Drawn(const cv::Mat& picture) {
  cv::Mat grey;
  cv::cvtColor(picture, grey, cv::COLOR_RGB2GRAY);
  std::vector<cv::Point> points;
  cv::findNonZero(grey, points);
  return points;
}

// The angle of the principal direction of `points` from the picture's x axis, degrees in (-90, 90].
double PrincipalAngleDeg(const std::vector<cv::Point>& points) {
  cv::Mat data(static_cast<int>(points.size()), 2, CV_64F);
  for (size_t i = 0; i < points.size(); ++i) {
    data.at<double>(static_cast<int>(i), 0) = points[i].x;
    data.at<double>(static_cast<int>(i), 1) = points[i].y;
  }
  cv::PCA pca(data, cv::Mat(), cv::PCA::DATA_AS_ROW);
  const double angle = std::atan2(pca.eigenvectors.at<double>(0, 1), pca.eigenvectors.at<double>(0, 0));
  double degrees = angle * 180.0 / M_PI;
  if (degrees > 90) degrees -= 180;
  if (degrees <= -90) degrees += 180;
  return degrees;
}

// Only the cells of one row (or one column) returned, in white.
Scan OnlyCells(const Scan& scan, cv::Rect cells) {
  cv::Mat keep(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  keep(cells).setTo(255);
  Scan only = MaskScan(scan, keep);
  only.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(255));
  return only;
}

TEST(RenderView, TheUpOfTheScanStaysUpWhateverItsPose) {
  Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  // The scan posed as a camera-like cloud: scanner z along world -y (an optical frame), as the PCD reader
  // poses organized clouds.
  Eigen::Matrix4d camera_from_scanner = Eigen::Matrix4d::Zero();
  camera_from_scanner(0, 0) = 1;
  camera_from_scanner(1, 2) = -1;
  camera_from_scanner(2, 1) = 1;
  camera_from_scanner(3, 3) = 1;
  scan.world_from_scanner = camera_from_scanner;
  EXPECT_TRUE(ScanUpInWorld(scan).isApprox(Eigen::Vector3d(0, -1, 0)));
  const cv::Mat everything = scan.valid != 0;
  // The box's front face is vertical: the column of cells through its middle is a vertical segment.
  const cv::Rect box = cv::boundingRect(scan.label == 1);
  ASSERT_GT(box.height, 10);
  const int col = box.x + box.width / 2;
  const Scan column = OnlyCells(scan, cv::Rect(col, box.y + 1, 1, box.height - 2));
  const Scan top = OnlyCells(scan, cv::Rect(col, box.y + 1, 1, 1));
  const Scan bottom = OnlyCells(scan, cv::Rect(col, box.br().y - 2, 1, 1));
  for (const double angle : {0.0, 30.0, -45.0}) {
    const PointViewOptions view = SideView(scan, everything, angle);
    EXPECT_TRUE(view.up_in_world.isApprox(Eigen::Vector3d(0, -1, 0)));
    // It stands upright in the picture, its top above its bottom (within the few degrees by which verticals
    // converge when the camera looks down on them away from the picture's centre; a rolled camera is tens of
    // degrees off).
    const std::vector<cv::Point> drawn = Drawn(RenderPointView(column, view));
    ASSERT_GT(drawn.size(), 10u);
    EXPECT_NEAR(std::abs(PrincipalAngleDeg(drawn)), 90.0, 6.0) << angle;
    const auto top_drawn = Drawn(RenderPointView(top, view)),
               bottom_drawn = Drawn(RenderPointView(bottom, view));
    ASSERT_FALSE(top_drawn.empty());
    ASSERT_FALSE(bottom_drawn.empty());
    EXPECT_LT(top_drawn[0].y, bottom_drawn[0].y) << angle;
  }
}

TEST(RenderView, TheCameraAroundARegionIgnoresWhatTheRegionHolds) {
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  const cv::Mat region = scan.label == 1;  // the box
  ASSERT_GT(cv::countNonZero(region), 100);
  // An edit inside the region: the box's cells pushed back 2 m, some left without a return.
  Scan edited = Clone(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!region.at<uint8_t>(row, col)) continue;
      if ((row + col) % 5 == 0) {
        edited.valid.at<uint8_t>(row, col) = 0;
        edited.range.at<float>(row, col) = 0;
        edited.point.at<cv::Vec3f>(row, col) = cv::Vec3f(0, 0, 0);
        continue;
      }
      const float range = scan.range.at<float>(row, col) + 2.0f;
      edited.range.at<float>(row, col) = range;
      edited.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
    }
  }
  // A reader that fits the grid to the returns (E57, PTX of real scans) moves every cell's direction a little
  // when the returns inside the region change.
  edited.direction.forEach<cv::Vec3f>(
      [](cv::Vec3f& d, const int*) { d = cv::normalize(d + cv::Vec3f(1e-4f, -2e-4f, 1e-4f)); });
  for (const double angle : {0.0, 35.0}) {
    const PointViewOptions before = SideView(scan, region, angle), after = SideView(edited, region, angle);
    EXPECT_EQ(before.eye_in_world, after.eye_in_world);
    EXPECT_EQ(before.target_in_world, after.target_in_world);
    EXPECT_EQ(before.up_in_world, after.up_in_world);
    // The same pixels wherever neither version's region points are drawn.
    const cv::Mat picture_before = RenderPointView(scan, before),
                  picture_after = RenderPointView(edited, after);
    cv::Mat edited_pixels(picture_before.size(), CV_8U, cv::Scalar(0));
    for (const Scan* s : {&scan, static_cast<const Scan*>(&edited)}) {
      Scan only_region = MaskScan(*s, region);
      only_region.color = cv::Mat(s->rows, s->cols, CV_8UC3, cv::Scalar::all(255));
      cv::Mat grey;
      cv::cvtColor(RenderPointView(only_region, before), grey, cv::COLOR_RGB2GRAY);
      edited_pixels |= grey != 0;
    }
    cv::Mat differ;
    cv::cvtColor(cv::Mat(picture_before != picture_after), differ, cv::COLOR_RGB2GRAY);
    const int unchanged_differ = cv::countNonZero((differ != 0) & (edited_pixels == 0));
    EXPECT_EQ(unchanged_differ, 0) << angle;
    EXPECT_GT(cv::countNonZero(differ), 0) << angle;  // the edit itself shows
  }
}

TEST(RenderView, CameraFileRoundTripsAndRefusesNonsense) {
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  PointViewOptions view = SideView(scan, scan.valid != 0, 20.0);
  view.field_of_view_deg = 45;
  view.width_px = 300;
  view.height_px = 200;
  PointViewOptions read;
  ParseCameraJson(ToJson(CameraOf(view, scan)).dump(), "cam.json", &read);
  EXPECT_EQ(read.eye_in_world, view.eye_in_world);
  EXPECT_EQ(read.target_in_world, view.target_in_world);
  EXPECT_EQ(read.up_in_world, view.up_in_world);
  EXPECT_EQ(read.field_of_view_deg, 45);
  EXPECT_EQ(read.width_px, 300);
  EXPECT_EQ(cv::countNonZero(cv::Mat(RenderPointView(scan, read) != RenderPointView(scan, view)).reshape(1)),
            0);
  PointViewOptions bad;
  for (const std::string text :
       {"[]", "{\"eye\": [0, 0, 0], \"target\": [0, 1, 0]}",
        "{\"eye\": [0, 0, 0], \"target\": [0, 1, 0], \"up\": [0, 2, 0]}",
        "{\"eye\": [0, 0, 0], \"target\": [0, 1, 0], \"up\": [0, 0, 1], \"fov\": 40}",
        "{\"eye\": [0, 0, 0], \"target\": [0, 1, 0], \"up\": [0, 0, 1], \"width\": 5}",
        "{\"eye\": [0, 0], \"target\": [0, 1, 0], \"up\": [0, 0, 1]}"}) {
    EXPECT_THROW(ParseCameraJson(text, "cam.json", &bad), InputError) << text;
  }
}

// The mug of PCL's stereo data (an organized camera-like cloud): seen from its own camera, its rows stay
// level and its columns upright (the picture is not rolled); the camera's up is the camera's -y.
TEST(RenderView, TheMugIsUprightFromItsCamera) {
  const std::string path = LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd";
  const Scan scan = ReadScanFile(path).scans.at(0);
  const Eigen::Matrix3d world_from_optical =
      scan.world_from_scanner.topLeftCorner<3, 3>() *
      (Eigen::Matrix3d() << 1, 0, 0, 0, 0, 1, 0, -1, 0).finished();  // scanner_from_optical
  const PointViewOptions view = SideView(scan, scan.valid != 0, 0.0);
  EXPECT_TRUE(view.up_in_world.isApprox(world_from_optical * Eigen::Vector3d(0, -1, 0)));
  const double row_angle = PrincipalAngleDeg(
      Drawn(RenderPointView(OnlyCells(scan, cv::Rect(0, scan.rows / 2, scan.cols, 1)), view)));
  EXPECT_NEAR(row_angle, 0.0, 3.0);
  const double column_angle = PrincipalAngleDeg(
      Drawn(RenderPointView(OnlyCells(scan, cv::Rect(scan.cols / 2, 0, 1, scan.rows)), view)));
  EXPECT_NEAR(std::abs(column_angle), 90.0, 3.0);
  // 30° around: the same up.
  EXPECT_TRUE(SideView(scan, scan.valid != 0, 30.0).up_in_world.isApprox(view.up_in_world));
}

}  // namespace
}  // namespace lidarshop
