// The ground under a scan, and second viewpoints kept level on it.
#include "lidarshop/pointset/ground.h"

#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/render_view.h"
#include "lidarshop/testing/scenes.h"

namespace lidarshop {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

TEST(Ground, FoundUnderATerrestrialScanWhateverItsPose) {
  Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  const auto ground = FindGround(scan);
  ASSERT_TRUE(ground);
  EXPECT_LT(AngleDeg(ground->normal_in_world, Eigen::Vector3d::UnitZ()), 0.5);
  EXPECT_GT(ground->share, 0.3);
  // The same scan posed elsewhere: the normal turns with it.
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  scan.world_from_scanner.topLeftCorner<3, 3>() = rotation;
  const auto turned = FindGround(scan);
  ASSERT_TRUE(turned);
  EXPECT_LT(AngleDeg(turned->normal_in_world, rotation * Eigen::Vector3d::UnitZ()), 0.5);
}

TEST(Ground, NotFoundOnAWall) {
  // The scene with the ground left out: only the box's faces, which stand upright.
  test_scenes::GroundAndBoxOptions options;
  options.ground_size = 0.001;
  options.box_size = Eigen::Vector3d(8, 0.5, 6);
  options.box_center = Eigen::Vector3d(0, 8, 1.5);
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(options));
  ASSERT_GT(scan.CountValid(), 1000);
  EXPECT_FALSE(FindGround(scan));
}

// PCL's stereo mug: the camera looks down at the table, 33° from it. The orbit about the table's normal keeps
// the table's normal pointing up in the picture.
TEST(Ground, TheMugsTableStaysLevelInSecondViewpoints) {
  const std::string path = LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd";
  const Scan scan = ReadScanFile(path).scans.at(0);
  const auto ground = FindGround(scan);
  ASSERT_TRUE(ground);
  EXPECT_GT(ground->share, 0.4);
  EXPECT_GT(ground->tilt_deg, 20);  // the camera is tilted against the table
  EXPECT_LT(ground->tilt_deg, 50);
  // The centre the camera looks at and a point 30 cm above it along the normal, drawn from 0° and 30° around:
  // the second straight above the first (at the picture's centre, where perspective does not tilt verticals).
  const Eigen::Matrix4d scanner_from_world = scan.world_from_scanner.inverse();
  for (const double angle : {0.0, 30.0, -30.0}) {
    const PointViewOptions view = SideView(scan, scan.valid != 0, angle, ground->normal_in_world);
    const Eigen::Vector3d centre = view.target_in_world;
    const Eigen::Vector3d above_centre = centre + 0.3 * ground->normal_in_world;
    cv::Point2d drawn[2];
    for (int k = 0; k < 2; ++k) {
      Scan one = MakeScan(1, 1, /*with_color=*/true);
      one.world_from_scanner = scan.world_from_scanner;
      one.valid.at<uint8_t>(0, 0) = kValid;
      const Eigen::Vector3d p =
          (scanner_from_world * (k == 0 ? centre : above_centre).homogeneous()).head<3>();
      one.point.at<cv::Vec3f>(0, 0) = cv::Vec3f(p.x(), p.y(), p.z());
      one.range.at<float>(0, 0) = static_cast<float>(cv::norm(one.point.at<cv::Vec3f>(0, 0)));
      one.color.at<cv::Vec3b>(0, 0) = cv::Vec3b(255, 255, 255);
      cv::Mat grey;
      cv::cvtColor(RenderPointView(one, view), grey, cv::COLOR_RGB2GRAY);
      const cv::Moments m = cv::moments(grey, true);
      ASSERT_GT(m.m00, 0) << angle;
      drawn[k] = cv::Point2d(m.m10 / m.m00, m.m01 / m.m00);
    }
    const cv::Point2d up = drawn[1] - drawn[0];  // picture y grows downwards
    ASSERT_GT(cv::norm(up), 5.0) << angle;
    EXPECT_NEAR(std::atan2(up.x, -up.y) * 180.0 / M_PI, 0.0, 1.5) << angle;
  }
}

}  // namespace
}  // namespace lidarshop
