#include "lidarshop/geometry/camera.h"

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

PinholeCamera TestCamera() {
  PinholeCamera camera;
  camera.width_px = 640;
  camera.height_px = 480;
  camera.fx_px = 500;
  camera.fy_px = 510;
  camera.cx_px = 321.5;
  camera.cy_px = 238.25;
  camera.skew_px = 0.5;
  camera.k1 = -0.2;
  camera.k2 = 0.05;
  camera.k3 = 0.01;
  camera.p1 = 0.001;
  camera.p2 = -0.002;
  camera.world_from_camera = ComposeTransform({1, -2, 1.5}, {-100, 5, 20});
  return camera;
}

TEST(Camera, ProjectsThePrincipalPointAndHonoursThePixelConvention) {
  PinholeCamera camera = TestCamera();
  camera.k1 = camera.k2 = camera.k3 = camera.p1 = camera.p2 = 0;
  Eigen::Vector2d pixel;
  ASSERT_TRUE(ProjectCameraPoint(camera, {0, 0, 3}, &pixel));
  EXPECT_NEAR(pixel.x(), 321.5, 1e-12);
  EXPECT_NEAR(pixel.y(), 238.25, 1e-12);
  // x right, y down: a point right of and below the axis lands right of and below the principal point.
  ASSERT_TRUE(ProjectCameraPoint(camera, {0.1, 0.2, 1}, &pixel));
  EXPECT_NEAR(pixel.x(), 321.5 + 500 * 0.1 + 0.5 * 0.2, 1e-9);
  EXPECT_NEAR(pixel.y(), 238.25 + 510 * 0.2, 1e-9);
  EXPECT_FALSE(ProjectCameraPoint(camera, {0, 0, -1}, &pixel));
  EXPECT_TRUE(InsideImage(camera, {0, 0}));
  EXPECT_TRUE(InsideImage(camera, {639.99, 479.99}));
  EXPECT_FALSE(InsideImage(camera, {640, 10}));
  EXPECT_FALSE(InsideImage(camera, {-0.01, 10}));
}

TEST(Camera, UnprojectInvertsProjectWithDistortion) {
  const PinholeCamera camera = TestCamera();
  for (double u = 5; u < 640; u += 57.3) {
    for (double v = 3; v < 480; v += 41.1) {
      const Eigen::Vector3d ray = UnprojectPixel(camera, {u, v});
      EXPECT_DOUBLE_EQ(ray.z(), 1.0);
      Eigen::Vector2d back;
      ASSERT_TRUE(ProjectCameraPoint(camera, 2.5 * ray, &back));
      EXPECT_NEAR(back.x(), u, 1e-6);
      EXPECT_NEAR(back.y(), v, 1e-6);
    }
  }
}

TEST(Camera, WorldPointsGoThroughThePose) {
  const PinholeCamera camera = TestCamera();
  const Eigen::Vector3d ray = UnprojectPixel(camera, {100, 400});
  const Eigen::Vector3d point_in_world =
      camera.world_from_camera.topLeftCorner<3, 3>() * (4.0 * ray) + camera.center_in_world();
  Eigen::Vector2d pixel;
  ASSERT_TRUE(ProjectWorldPoint(camera, point_in_world, &pixel));
  EXPECT_NEAR(pixel.x(), 100, 1e-6);
  EXPECT_NEAR(pixel.y(), 400, 1e-6);
}

TEST(Camera, LookingAtPutsTheTargetAtTheCentreWithTheSkyUp) {
  const PinholeCamera camera = CameraLookingAt({1, 0, 1.5}, {0, 10, 1}, 800, 600, 60);
  EXPECT_TRUE(IsRigid(camera.world_from_camera));
  EXPECT_NEAR(camera.fx_px, 400 / std::tan(M_PI / 6), 1e-9);
  Eigen::Vector2d pixel, above;
  ASSERT_TRUE(ProjectWorldPoint(camera, {0, 10, 1}, &pixel));
  EXPECT_NEAR(pixel.x(), 400, 1e-9);
  EXPECT_NEAR(pixel.y(), 300, 1e-9);
  ASSERT_TRUE(ProjectWorldPoint(camera, {0, 10, 3}, &above));
  EXPECT_LT(above.y(), pixel.y());  // higher in the world = higher in the image
}

TEST(Camera, JsonRoundTripIsExact) {
  const PinholeCamera camera = TestCamera();
  const PinholeCamera back = ParseCameraJson(CameraToJson(camera), "cam.json");
  EXPECT_EQ(back.width_px, 640);
  EXPECT_EQ(back.height_px, 480);
  EXPECT_EQ(back.fx_px, camera.fx_px);
  EXPECT_EQ(back.cy_px, camera.cy_px);
  EXPECT_EQ(back.skew_px, camera.skew_px);
  EXPECT_EQ(back.k3, camera.k3);
  EXPECT_EQ(back.p2, camera.p2);
  EXPECT_EQ(back.world_from_camera, camera.world_from_camera);
}

TEST(Camera, JsonErrorsNameTheField) {
  const std::string pose = R"("world_from_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]])";
  // Skew and distortion are optional.
  EXPECT_NO_THROW(ParseCameraJson(
      R"({"width_px": 4, "height_px": 3, "fx_px": 1, "fy_px": 1, "cx_px": 2, "cy_px": 1.5, )" + pose + "}",
      "c"));
  try {
    ParseCameraJson(R"({"width_px": 4, "height_px": 3, "fx_px": 1, "cx_px": 2, "cy_px": 1.5, )" + pose + "}",
                    "cam.json");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("cam.json"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("'fy_px': missing"), std::string::npos) << error.what();
  }
  EXPECT_THROW(ParseCameraJson(R"({"width_px": 4, "height_px": 3, "fx_px": 1, "fy_px": 1, "cx_px": 2,
                                   "cy_px": 1.5})",
                               "c"),
               InputError);
  EXPECT_THROW(ParseCameraJson(R"({"width_px": 4, "height_px": 3, "fx_px": -1, "fy_px": 1, "cx_px": 2,
                                   "cy_px": 1.5, )" +
                                   pose + "}",
                               "c"),
               InputError);
  EXPECT_THROW(ParseCameraJson(R"({"width_px": 4, "height_px": 3, "fx_px": 1, "fy_px": 1, "cx_px": 2,
                                   "cy_px": 1.5, "world_from_camera": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})",
                               "c"),
               InputError);
  EXPECT_THROW(ParseCameraJson("{not json", "c"), InputError);
}

}  // namespace
}  // namespace lidarshop
