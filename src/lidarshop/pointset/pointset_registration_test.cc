// Point-to-plane ICP on two synthetic scans of one scene from two scanner positions: the relative pose is
// known, the moving scan starts from a perturbed pose and must come back within 1 mm and 0.01°.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/features.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Ground, the test box, and two turned copies of it (planes facing every way, so every axis is constrained).
SceneDescription ThreeBoxScene() {
  test_scenes::GroundAndBoxOptions options;
  options.azimuth_half_deg = 60.0;
  SceneDescription scene = test_scenes::MakeGroundAndBoxScene(options);
  const SceneObject box = scene.objects[1];
  for (const auto& [offset, angle] : {std::pair{Eigen::Vector3d(-0.5, 0.5, 0.0), 35.0},
                                      std::pair{Eigen::Vector3d(1.5, -2.0, 0.3), -25.0}}) {
    SceneObject copy = box;
    copy.world_from_object = ComposeTransform(offset, Eigen::Vector3d(0, 0, angle)) * box.world_from_object;
    scene.objects.push_back(copy);
  }
  return scene;
}

ScannerOptions Scanner(const SceneDescription& scene, const Eigen::Vector3d& position, double yaw_deg) {
  ScannerOptions scanner = test_scenes::SmallScanner(scene.scanner, 240, 480);
  scanner.position = position;
  scanner.rotate_deg = Eigen::Vector3d(0, 0, yaw_deg);
  scanner.los_noise_sigma_m = 0.002;
  return scanner;
}

double AngleDeg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const Eigen::Matrix3d r = a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>();
  return Eigen::AngleAxisd(r).angle() * 180.0 / M_PI;
}

TEST(RegistrationTest, IcpRecoversTheRelativePoseOfTwoScans) {
  const SceneDescription scene = ThreeBoxScene();
  const Scan fixed = test_scenes::ScanScene(scene, Scanner(scene, {0, 0, 1.5}, 0.0));
  ScannerOptions moving_scanner = Scanner(scene, {0.8, -0.6, 1.6}, 8.0);
  moving_scanner.seed = 2;
  const Scan moving_true = test_scenes::ScanScene(scene, moving_scanner);
  ASSERT_GT(fixed.CountValid(), 50000);
  // The initial guess is off by 8 cm and 1.5°.
  Scan moving = moving_true;
  moving.world_from_scanner =
      ComposeTransform({0.05, -0.04, 0.05}, {0.5, -0.5, 1.5}) * moving_true.world_from_scanner;
  const ScanRegistration registration = RegisterScans(fixed, moving, {.max_correspondence_m = 0.3});
  const Eigen::Matrix4d& found = registration.registered.world_from_scanner;
  const Eigen::Matrix4d& truth = moving_true.world_from_scanner;
  std::printf("ICP: %d iterations, translation error %.3g m, rotation error %.3g deg, fitness %.3f\n",
              registration.icp.iterations,
              (found.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), AngleDeg(found, truth),
              registration.icp.fitness);
  EXPECT_TRUE(registration.icp.converged)
      << registration.icp.iterations << " iterations, rms " << registration.icp.rms_m;
  EXPECT_LT((found.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.001);
  EXPECT_LT(AngleDeg(found, truth), 0.01);
  EXPECT_GT(registration.icp.fitness, 0.5);
  EXPECT_LT(registration.icp.rms_m, 0.005);
  // Same answer on one thread.
  ThreadLimit one(1);
  EXPECT_EQ(RegisterScans(fixed, moving, {.max_correspondence_m = 0.3}).registered.world_from_scanner, found);
}

TEST(RegistrationTest, FpfhRansacThenIcpWithoutAGuess) {
  const SceneDescription scene = ThreeBoxScene();
  const Scan fixed = test_scenes::ScanScene(scene, Scanner(scene, {0, 0, 1.5}, 0.0));
  const Scan moving_true = test_scenes::ScanScene(scene, Scanner(scene, {0.8, -0.6, 1.6}, 8.0));
  // No usable guess: 1.2 m and 30° off.
  Scan moving = moving_true;
  moving.world_from_scanner = ComposeTransform({1.0, -0.7, 0.1}, {0, 0, 30}) * moving_true.world_from_scanner;
  const PointCloud fixed_cloud = ToPointCloud(fixed, true), moving_cloud = ToPointCloud(moving, true);
  const GlobalAlignResult global = AlignGlobally(
      fixed_cloud, moving_cloud, {.voxel_m = 0.2, .feature_radius_m = 0.8, .inlier_distance_m = 0.3});
  const IcpResult icp = IcpPointToPlane(fixed_cloud, moving_cloud, global.fixed_from_moving, {});
  const Eigen::Matrix4d found = icp.fixed_from_moving * moving.world_from_scanner;
  const Eigen::Matrix4d& truth = moving_true.world_from_scanner;
  const Eigen::Matrix4d rough = global.fixed_from_moving * moving.world_from_scanner;
  std::printf("global: %lld matches, %lld inliers, off by %.3g m and %.3g deg; after ICP %.3g m, %.3g deg\n",
              static_cast<long long>(global.matches), static_cast<long long>(global.inliers),
              (rough.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), AngleDeg(rough, truth),
              (found.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), AngleDeg(found, truth));
  EXPECT_LT((rough.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.2);
  EXPECT_LT(AngleDeg(rough, truth), 3.0);
  EXPECT_LT((found.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.001);
  EXPECT_LT(AngleDeg(found, truth), 0.01);
}

TEST(RegistrationTest, BadInput) {
  PointCloud empty, line;
  for (int i = 0; i < 10; ++i) line.points.emplace_back(i, 0, 0);
  EXPECT_THROW(IcpPointToPlane(empty, line, Eigen::Matrix4d::Identity(), {}), InputError);
  EXPECT_THROW(IcpPointToPlane(line, line, Eigen::Matrix4d::Identity(), {.max_correspondence_m = 0.0}),
               OptionsError);
}

}  // namespace
}  // namespace lidarshop
