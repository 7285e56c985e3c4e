#include "lidarshop/geometry/camera_model.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

Camera Pinhole() {
  PinholeCamera pinhole;
  pinhole.width_px = 640, pinhole.height_px = 480;
  pinhole.fx_px = 500, pinhole.fy_px = 510, pinhole.cx_px = 321.5, pinhole.cy_px = 238.25;
  pinhole.skew_px = 0.7, pinhole.k1 = -0.12, pinhole.k2 = 0.03, pinhole.p1 = 1e-3, pinhole.p2 = -2e-3;
  pinhole.world_from_camera = ComposeTransform({1, 2, 1.5}, {-80, 5, 30});
  return CameraFromPinhole(pinhole);
}

Camera Fisheye() {
  Camera camera;
  camera.model = CameraModel::kFisheye;
  camera.pinhole.width_px = 1000, camera.pinhole.height_px = 1000;
  camera.pinhole.fx_px = 300, camera.pinhole.fy_px = 305, camera.pinhole.cx_px = 500.5;
  camera.pinhole.cy_px = 499, camera.pinhole.skew_px = 0.2;
  camera.fisheye_k[0] = -0.02, camera.fisheye_k[1] = 0.004, camera.fisheye_k[2] = -1e-4;
  camera.fisheye_k[3] = 1e-5;
  camera.world_from_camera = ComposeTransform({-1, 0.5, 2}, {10, 20, 30});
  return camera;
}

Camera Spherical() { return SphericalPanorama(500, ComposeTransform({0.2, -0.3, 1.65}, {0, 0, 15})); }

Camera Cylindrical() {
  Camera camera;
  camera.model = CameraModel::kCylindrical;
  camera.pinhole.width_px = 3600, camera.pinhole.height_px = 1200;
  camera.pixel_width_rad = 2 * M_PI / 3600;
  camera.radius_m = 0.5;
  camera.pixel_height_m = 0.5 * M_PI / 3600 * 1.1;
  camera.principal_y_px = 640.5;
  camera.world_from_camera = ComposeTransform({3, 1, 1.2}, {2, -3, 100});
  return camera;
}

std::vector<Camera> AllModels() { return {Pinhole(), Fisheye(), Spherical(), Cylindrical()}; }

// A random direction the camera sees: a random pixel's ray, perturbed, projected to a pixel inside the image.
TEST(CameraModel, UnprojectOfProjectGivesTheDirectionBack) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const Camera& camera : AllModels()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    camera.Check();
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
      Eigen::Vector3d direction(unit(random), unit(random), unit(random));
      if (direction.norm() < 1e-3) continue;
      direction.normalize();
      Eigen::Vector2d pixel;
      if (!ProjectCameraPoint(camera, 3.7 * direction, &pixel) || !InsideImage(camera, pixel)) continue;
      Eigen::Vector3d back;
      ASSERT_TRUE(UnprojectPixel(camera, pixel, &back));
      EXPECT_NEAR(back.norm(), 1.0, 1e-12);
      ASSERT_LT((back - direction).norm(), 1e-9) << direction.transpose() << " -> " << pixel.transpose();
      ++checked;
    }
    // Every model sees a good share of the sphere (the pinhole the least).
    EXPECT_GT(checked, 1000);
  }
}

TEST(CameraModel, PixelsOfKnownDirections) {
  Eigen::Vector2d pixel;
  // Fisheye: a ray 90° off the axis along +x lands at fx · (π/2)(1 + k1 θ² + ...) right of the centre.
  Camera fisheye = Fisheye();
  fisheye.pinhole.skew_px = 0;
  const double theta = M_PI / 2, t2 = theta * theta;
  const double theta_d = theta * (1 + t2 * (-0.02 + t2 * (0.004 + t2 * (-1e-4 + t2 * 1e-5))));
  ASSERT_TRUE(ProjectCameraPoint(fisheye, {2, 0, 0}, &pixel));
  EXPECT_NEAR(pixel.x(), 500.5 + 300 * theta_d, 1e-9);
  EXPECT_NEAR(pixel.y(), 499, 1e-9);
  ASSERT_TRUE(ProjectCameraPoint(fisheye, {0, 0, 5}, &pixel));  // the axis: the principal point
  EXPECT_NEAR(pixel.x(), 500.5, 1e-12);
  EXPECT_FALSE(ProjectCameraPoint(fisheye, {0, 0, -1}, &pixel));  // straight behind: every pixel of a circle

  // Spherical (1000 x 500): +y is the image centre; +x (right) a quarter turn right; up the top edge.
  const Camera sphere = Spherical();
  ASSERT_TRUE(ProjectCameraPoint(sphere, {0, 1, 0}, &pixel));
  EXPECT_NEAR(pixel.x(), 500, 1e-9);
  EXPECT_NEAR(pixel.y(), 250, 1e-9);
  ASSERT_TRUE(ProjectCameraPoint(sphere, {1, 0, 0}, &pixel));
  EXPECT_NEAR(pixel.x(), 750, 1e-9);
  ASSERT_TRUE(ProjectCameraPoint(sphere, {0, -1, 0}, &pixel));  // behind: the right edge (θ = π)
  EXPECT_NEAR(pixel.x(), 1000, 1e-9);
  ASSERT_TRUE(ProjectCameraPoint(sphere, {0, 1, 1}, &pixel));  // 45° up: a quarter of the way from the top
  EXPECT_NEAR(pixel.y(), 125, 1e-9);
  Eigen::Vector3d ray;
  EXPECT_FALSE(UnprojectPixel(sphere, {10, -1}, &ray));  // above the pole
  EXPECT_FALSE(ProjectCameraPoint(sphere, {0, 0, 0}, &pixel));

  // Cylindrical: the horizon row is principal_y_px; a point 1 m out and 0.2 m up meets the cylinder of
  // radius 0.5 at 0.1 m, 0.1 / pixel_height_m rows above it.
  const Camera cylinder = Cylindrical();
  ASSERT_TRUE(ProjectCameraPoint(cylinder, {0, 1, 0.2}, &pixel));
  EXPECT_NEAR(pixel.x(), 1800, 1e-9);
  EXPECT_NEAR(pixel.y(), 640.5 - 0.1 / cylinder.pixel_height_m, 1e-9);
  ASSERT_TRUE(ProjectCameraPoint(cylinder, {-3, 0, 0}, &pixel));  // left: a quarter turn left
  EXPECT_NEAR(pixel.x(), 900, 1e-9);
  EXPECT_FALSE(ProjectCameraPoint(cylinder, {0, 0, 2}, &pixel));  // on the axis

  // Pinhole: the same pixels as geometry/camera.h.
  const Camera pinhole = Pinhole();
  const Eigen::Vector3d point(0.3, -0.2, 2.0);
  Eigen::Vector2d expected;
  ASSERT_TRUE(ProjectCameraPoint(pinhole.pinhole, point, &expected));
  ASSERT_TRUE(ProjectCameraPoint(pinhole, point, &pixel));
  EXPECT_EQ(pixel, expected);
}

TEST(CameraModel, WorldPointsGoThroughThePose) {
  for (const Camera& camera : AllModels()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    Eigen::Vector3d ray;
    ASSERT_TRUE(UnprojectPixel(camera, {0.4 * camera.width_px(), 0.45 * camera.height_px()}, &ray));
    const Eigen::Vector3d point_in_world =
        camera.world_from_camera.topLeftCorner<3, 3>() * (6.0 * ray) + camera.center_in_world();
    Eigen::Vector2d pixel;
    ASSERT_TRUE(ProjectWorldPoint(camera, point_in_world, &pixel));
    EXPECT_NEAR(pixel.x(), 0.4 * camera.width_px(), 1e-7);
    EXPECT_NEAR(pixel.y(), 0.45 * camera.height_px(), 1e-7);
  }
}

TEST(CameraModel, JsonRoundTripIsExact) {
  for (const Camera& camera : AllModels()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    const std::string text = CameraModelToJson(camera);
    EXPECT_NE(text.find(std::string("\"model\": \"") + CameraModelName(camera.model) + "\""),
              std::string::npos);
    const Camera back = ParseCameraModelJson(text, "cam.json");
    EXPECT_EQ(back.model, camera.model);
    EXPECT_EQ(back.width_px(), camera.width_px());
    EXPECT_EQ(back.height_px(), camera.height_px());
    EXPECT_EQ(back.world_from_camera, camera.world_from_camera);
    EXPECT_EQ(back.pinhole.fx_px, camera.pinhole.fx_px);
    EXPECT_EQ(back.pinhole.cy_px, camera.pinhole.cy_px);
    EXPECT_EQ(back.pinhole.skew_px, camera.pinhole.skew_px);
    EXPECT_EQ(back.pinhole.k1, camera.pinhole.k1);
    EXPECT_EQ(back.pinhole.p2, camera.pinhole.p2);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(back.fisheye_k[i], camera.fisheye_k[i]);
    EXPECT_EQ(back.pixel_width_rad, camera.pixel_width_rad);
    EXPECT_EQ(back.pixel_height_rad, camera.pixel_height_rad);
    EXPECT_EQ(back.pixel_height_m, camera.pixel_height_m);
    EXPECT_EQ(back.radius_m, camera.radius_m);
    EXPECT_EQ(back.principal_y_px, camera.principal_y_px);
  }
}

TEST(CameraModel, PinholeJsonWithoutAModelReadsUnchanged) {
  const PinholeCamera pinhole = Pinhole().AsPinhole();
  const Camera back = ParseCameraModelJson(CameraToJson(pinhole), "old.json");
  EXPECT_EQ(back.model, CameraModel::kPinhole);
  EXPECT_EQ(back.AsPinhole().K(), pinhole.K());
  EXPECT_EQ(back.world_from_camera, pinhole.world_from_camera);
  // And a pinhole file with "model" still reads as a PinholeCamera; other models are refused there.
  EXPECT_NO_THROW(ParseCameraJson(CameraModelToJson(Pinhole()), "cam.json"));
  try {
    ParseCameraJson(CameraModelToJson(Fisheye()), "fish.json");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("fish.json"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("'model'"), std::string::npos) << error.what();
  }
}

TEST(CameraModel, JsonErrorsNameTheField) {
  const std::string pose = R"("world_from_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]])";
  const auto message = [](const std::string& text) {
    try {
      ParseCameraModelJson(text, "cam.json");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"model": "orthographic", "width_px": 4, "height_px": 3, )" + pose + "}")
                .find("'model': unknown model 'orthographic'"),
            std::string::npos);
  EXPECT_NE(message(R"({"model": "spherical", "width_px": 4, "height_px": 3, "pixel_width_rad": 0.1, )" +
                    pose + "}")
                .find("'pixel_height_rad': missing"),
            std::string::npos);
  EXPECT_NE(message(R"({"model": "cylindrical", "width_px": 4, "height_px": 3, "pixel_width_rad": 0.1,
                        "pixel_height_m": 0.01, "radius_m": 0, "principal_y_px": 1, )" +
                    pose + "}")
                .find("'radius_m': must be a finite number > 0"),
            std::string::npos);
  EXPECT_NE(message(R"({"model": "fisheye", "width_px": 4, "height_px": 3, "fx_px": 1, "fy_px": 1,
                        "cx_px": 2, "cy_px": 1.5, "distortion": {"k1": -1}, )" +
                    pose + "}")
                .find("'distortion': θd(θ) must grow"),
            std::string::npos);
  EXPECT_NE(message(R"({"model": "fisheye", "width_px": 4, "height_px": 3, "fx_px": 1, "fy_px": 1,
                        "cx_px": 2, "cy_px": 1.5, "distortion": {"p1": 0.1}, )" +
                    pose + "}")
                .find("'p1' is not a fisheye coefficient"),
            std::string::npos);
  EXPECT_NE(message(R"({"model": "spherical", "width_px": 4, "height_px": 3, "pixel_width_rad": 0.1,
                        "pixel_height_rad": 0.1})")
                .find("'world_from_camera': missing"),
            std::string::npos);
  // The shared pose reader (geometry/camera_json.h): a row of the wrong length is named too.
  EXPECT_NE(message(R"({"model": "spherical", "width_px": 4, "height_px": 3, "pixel_width_rad": 0.1,
                        "pixel_height_rad": 0.1, "world_from_camera": [[1,0,0,0],[0,1,0],[0,0,1,0],[0,0,0,1]]})")
                .find("'world_from_camera': expected 4 rows of 4 numbers"),
            std::string::npos);
  // Files: a missing one and a folder are refused naming the path (util/input_file.h), never read.
  for (const std::string path : {std::string("/nonexistent/cam.json"), std::string("/tmp")}) {
    try {
      ReadCameraModelJson(path);
      ADD_FAILURE() << path << " was read";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
    EXPECT_THROW(ReadCameraJson(path), InputError) << path;
  }
  EXPECT_NE(message("{not json").find("cam.json"), std::string::npos);
}

}  // namespace
}  // namespace lidarshop
