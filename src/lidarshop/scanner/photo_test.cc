#include "lidarshop/scanner/photo.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A camera 1.2 m right of the scanner of MakeGroundAndBoxScene, looking at the box (+y).
PinholeCamera CameraBesideScanner() {
  PinholeCamera camera;
  camera.width_px = 320;
  camera.height_px = 240;
  camera.fx_px = camera.fy_px = 300;
  camera.cx_px = 160;
  camera.cy_px = 120;
  // Camera z (forward) = world +y, camera x = world +x, camera y (down) = world -z.
  camera.world_from_camera = ComposeTransform({1.2, 0, 1.5}, {-90, 0, 0});
  return camera;
}

TEST(Photo, SeesTheSceneWithTheScannersColours) {
  test_scenes::GroundAndBoxOptions scene_options;
  scene_options.ground_texture = false;
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene(scene_options);
  const PinholeCamera camera = CameraBesideScanner();
  const Photo photo = RenderPhoto(scene, camera);
  ASSERT_EQ(photo.image.size(), cv::Size(320, 240));
  // The box centre (0, 8, 0.5) and a ground point (1.2, 4, 0) project onto the box and the ground.
  Eigen::Vector2d box_pixel, ground_pixel;
  ASSERT_TRUE(ProjectWorldPoint(camera, {0, 8, 0.5}, &box_pixel));
  ASSERT_TRUE(ProjectWorldPoint(camera, {1.2, 4, 0}, &ground_pixel));
  const auto at = [&](const cv::Mat& image, const Eigen::Vector2d& pixel) {
    return std::pair<int, int>(static_cast<int>(pixel.y()), static_cast<int>(pixel.x()));
  };
  const auto [box_row, box_col] = at(photo.image, box_pixel);
  const auto [ground_row, ground_col] = at(photo.image, ground_pixel);
  EXPECT_EQ(photo.label.at<int32_t>(box_row, box_col), 1);
  EXPECT_EQ(photo.label.at<int32_t>(ground_row, ground_col), 0);
  EXPECT_NEAR(photo.depth_m.at<float>(ground_row, ground_col), std::sqrt(16 + 1.5 * 1.5), 0.05);
  // The colours are the scan's: compare with the scan cells that see the same labels.
  const Scan scan = test_scenes::ScanScene(scene);
  cv::Vec3b scan_box, scan_ground;
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (scan.label.at<int32_t>(r, c) == 1) scan_box = scan.color.at<cv::Vec3b>(r, c);
      if (scan.label.at<int32_t>(r, c) == 0) scan_ground = scan.color.at<cv::Vec3b>(r, c);
    }
  }
  EXPECT_EQ(photo.image.at<cv::Vec3b>(box_row, box_col), scan_box);
  EXPECT_EQ(photo.image.at<cv::Vec3b>(ground_row, ground_col), scan_ground);
  // The sky (top row) is the background colour.
  EXPECT_EQ(photo.label.at<int32_t>(0, 160), kNoLabel);
  EXPECT_EQ(photo.image.at<cv::Vec3b>(0, 160), cv::Vec3b(0, 0, 0));
}

TEST(Photo, TexturesMatchTheScanAtTheSamePoints) {
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene();  // grass ground, checker box
  const PinholeCamera camera = CameraBesideScanner();
  PhotoOptions options;
  options.samples_per_axis = 2;
  const Photo photo = RenderPhoto(scene, camera, options);
  const Scan scan = test_scenes::ScanScene(scene);
  // Box cells (checker, 1 m squares) away from the square edges: the photo sees the same colour there.
  int compared = 0, equal = 0;
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (scan.label.at<int32_t>(r, c) != 1) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
      Eigen::Vector2d pixel;
      if (!ProjectWorldPoint(
              camera, TransformPoint(scan.world_from_scanner, {p[0], p[1], p[2]}).cast<double>(), &pixel) ||
          !InsideImage(camera, pixel))
        continue;
      const int row = static_cast<int>(pixel.y()), col = static_cast<int>(pixel.x());
      if (photo.label.at<int32_t>(row, col) != 1) continue;
      ++compared;
      equal +=
          cv::norm(cv::Vec3i(photo.image.at<cv::Vec3b>(row, col)) - cv::Vec3i(scan.color.at<cv::Vec3b>(r, c)),
                   cv::NORM_INF) <= 10;
    }
  }
  ASSERT_GT(compared, 100);
  EXPECT_GT(equal, 0.9 * compared);
}

// Each model sees the red box (label 1) where it projects the box centre, in the box's colour, and the sky
// above the horizon; pixels without a ray are background.
TEST(Photo, EveryCameraModelSeesTheBoxWhereItProjects) {
  test_scenes::GroundAndBoxOptions scene_options;
  scene_options.ground_texture = false;
  const SceneDescription scene = test_scenes::MakeGroundAndBoxScene(scene_options);
  const Rgb8 box_rgb = scene.objects[1].material.color;
  const cv::Vec3b box_colour(box_rgb[0], box_rgb[1], box_rgb[2]);
  // Scanner-like frames (z up, y forward) 1.2 m right of the scanner, turned 20° left.
  const Eigen::Matrix4d scanner_like = ComposeTransform({1.2, 0, 1.5}, {0, 0, 20});
  std::vector<Camera> cameras;
  cameras.push_back(SphericalPanorama(180, scanner_like));
  Camera cylinder;
  cylinder.model = CameraModel::kCylindrical;
  cylinder.pinhole.width_px = 360, cylinder.pinhole.height_px = 200;
  cylinder.pixel_width_rad = 2 * M_PI / 360;
  cylinder.radius_m = 1;
  cylinder.pixel_height_m = 0.01;
  cylinder.principal_y_px = 90;
  cylinder.world_from_camera = scanner_like;
  cameras.push_back(cylinder);
  Camera fisheye;  // > 180° across, looking along +y (camera x right, y down, z forward)
  fisheye.model = CameraModel::kFisheye;
  fisheye.pinhole.width_px = fisheye.pinhole.height_px = 240;
  fisheye.pinhole.fx_px = fisheye.pinhole.fy_px = 45;
  fisheye.pinhole.cx_px = fisheye.pinhole.cy_px = 120;
  fisheye.fisheye_k[0] = 0.01;
  fisheye.world_from_camera = ComposeTransform({1.2, 0, 1.5}, {-90, 0, 20});
  cameras.push_back(fisheye);
  for (const Camera& camera : cameras) {
    SCOPED_TRACE(CameraModelName(camera.model));
    const Photo photo = RenderPhoto(scene, camera);
    ASSERT_EQ(photo.image.size(), cv::Size(camera.width_px(), camera.height_px()));
    Eigen::Vector2d box_pixel, sky_pixel;
    ASSERT_TRUE(ProjectWorldPoint(camera, {0, 8, 0.5}, &box_pixel));
    ASSERT_TRUE(InsideImage(camera, box_pixel));
    const int row = static_cast<int>(box_pixel.y()), col = static_cast<int>(box_pixel.x());
    EXPECT_EQ(photo.label.at<int32_t>(row, col), 1);
    EXPECT_EQ(photo.image.at<cv::Vec3b>(row, col), box_colour);
    EXPECT_NEAR(photo.depth_m.at<float>(row, col),
                (Eigen::Vector3d(0, 8, 0.5) - Eigen::Vector3d(1.2, 0, 1.5)).norm(), 0.6);
    ASSERT_TRUE(ProjectWorldPoint(camera, {-30, 40, 30}, &sky_pixel));
    ASSERT_TRUE(InsideImage(camera, sky_pixel));
    EXPECT_EQ(photo.label.at<int32_t>(static_cast<int>(sky_pixel.y()), static_cast<int>(sky_pixel.x())),
              kNoLabel);
    // The ground fills the bottom row of the panoramas (the camera stands on it).
    if (camera.model != CameraModel::kFisheye) {
      EXPECT_EQ(photo.label.at<int32_t>(camera.height_px() - 1, camera.width_px() / 2), 0);
    }
  }
  // The fisheye's corners lie beyond 180°: no ray, background.
  const Photo fish = RenderPhoto(scene, cameras.back());
  Eigen::Vector3d ray;
  EXPECT_FALSE(UnprojectPixel(cameras.back(), {0.5, 0.5}, &ray));
  EXPECT_EQ(fish.label.at<int32_t>(0, 0), kNoLabel);
  EXPECT_EQ(fish.image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
}

TEST(Photo, RefusesABrokenCamera) {
  PinholeCamera camera = CameraBesideScanner();
  camera.fx_px = 0;
  EXPECT_THROW(RenderPhoto(test_scenes::MakeGroundAndBoxScene(), camera), InputError);
  PhotoOptions options;
  options.samples_per_axis = 0;
  EXPECT_THROW(RenderPhoto(test_scenes::MakeGroundAndBoxScene(), CameraBesideScanner(), options),
               OptionsError);
}

}  // namespace
}  // namespace lidarshop
