#include "lidarshop/scanner/station_photos.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// The plain ground-and-box scene: a red box 8 m ahead on a uniformly coloured ground.
SceneDescription PlainScene() {
  test_scenes::GroundAndBoxOptions options;
  options.ground_texture = false;
  options.rows = 40, options.columns = 60;
  return test_scenes::MakeGroundAndBoxScene(options);
}

cv::Vec3b Scaled(const Rgb8& rgb, double gain) {
  return cv::Vec3b(cv::saturate_cast<uint8_t>(rgb[0] * gain), cv::saturate_cast<uint8_t>(rgb[1] * gain),
                   cv::saturate_cast<uint8_t>(rgb[2] * gain));
}

// The colour of `photo` (as read back from E57) where it sees `point_in_world`; false when it does not.
bool ColourAt(const Camera& camera, const cv::Mat& image, const Eigen::Vector3d& point_in_world,
              cv::Vec3b* rgb) {
  Eigen::Vector2d pixel;
  if (!ProjectWorldPoint(camera, point_in_world, &pixel) || !InsideImage(camera, pixel)) return false;
  *rgb = image.at<cv::Vec3b>(static_cast<int>(pixel.y()), static_cast<int>(pixel.x()));
  return true;
}

// Written into an E57 file and read back: count, models, poses (camera centre 0.15 m above the scanner's), and
// the colours of known points (the box, the ground in every direction, the sky) at each photo's gain.
void CheckStation(StationPhotoKind kind, size_t count, const std::string& model) {
  const SceneDescription scene = PlainScene();
  StationPhotoOptions options;
  options.kind = kind;
  options.size_px = 96;
  options.seed = 5;
  const std::vector<StationPhoto> photos = RenderStationPhotos(scene, scene.scanner, options);
  ASSERT_EQ(photos.size(), count);
  const Scan scan = test_scenes::ScanScene(scene);
  const E57File file = ReadE57Bytes(EncodeE57({scan}, StationPhotosToE57(photos), {}), "station.e57");
  ASSERT_EQ(file.images.size(), count);
  const Eigen::Vector3d scanner_centre = scan.world_from_scanner.topRightCorner<3, 1>();
  const Rgb8 ground = scene.objects[0].material.color, box = scene.objects[1].material.color;
  int box_seen = 0, grounds_seen = 0;
  bool gains_differ = false;
  for (size_t i = 0; i < count; ++i) {
    SCOPED_TRACE(photos[i].name);
    const E57Image& image = file.images[i];
    EXPECT_EQ(image.name, photos[i].name);
    EXPECT_EQ(image.associated_scan, 0);
    Camera camera;
    std::string why;
    ASSERT_TRUE(CameraModelOfE57Image(image, &camera, &why)) << why;
    EXPECT_EQ(CameraModelName(camera.model), model);
    EXPECT_LT((camera.center_in_world() - scanner_centre - Eigen::Vector3d(0, 0, 0.15)).norm(), 1e-9);
    const double gain = photos[i].gain;
    if (i == 0) EXPECT_EQ(gain, 1.0);
    EXPECT_GE(gain, 0.7);
    EXPECT_LE(gain, 1.3);
    gains_differ |= gain != 1.0;
    cv::Vec3b rgb;
    if (ColourAt(camera, image.image, {0, 8, 0.5}, &rgb)) {
      EXPECT_EQ(rgb, Scaled(box, gain));
      ++box_seen;
    }
    for (const Eigen::Vector3d& ground_point :
         {Eigen::Vector3d(0.3, 4, 0), Eigen::Vector3d(4, 0.3, 0), Eigen::Vector3d(-0.3, -4, 0),
          Eigen::Vector3d(-4, -0.3, 0), Eigen::Vector3d(0.2, 0.3, 0)}) {
      if (ColourAt(camera, image.image, ground_point, &rgb)) {
        EXPECT_EQ(rgb, Scaled(ground, gain)) << ground_point.transpose();
        ++grounds_seen;
      }
    }
    if (ColourAt(camera, image.image, scanner_centre + Eigen::Vector3d(0.1, 0.2, 10), &rgb))
      EXPECT_EQ(rgb, cv::Vec3b(0, 0, 0));  // the sky: background
  }
  EXPECT_EQ(box_seen, 1);      // in the panorama, or in the front face only
  EXPECT_EQ(grounds_seen, 5);  // each ground point in one photo
  EXPECT_EQ(gains_differ, count > 1);
}

TEST(StationPhotos, CubeMapOfSixFacesReadsBackWithPosesAndGains) {
  CheckStation(StationPhotoKind::kCube, 6, "pinhole");
}

TEST(StationPhotos, SphericalPanoramaReadsBackWithItsPose) {
  CheckStation(StationPhotoKind::kSphere, 1, "spherical");
}

TEST(StationPhotos, GainsComeFromTheSeed) {
  const SceneDescription scene = PlainScene();
  StationPhotoOptions options;
  options.kind = StationPhotoKind::kCube;
  options.size_px = 8;
  const auto gains = [&](uint64_t seed) {
    options.seed = seed;
    std::vector<double> result;
    for (const StationPhoto& photo : RenderStationPhotos(scene, scene.scanner, options))
      result.push_back(photo.gain);
    return result;
  };
  EXPECT_EQ(gains(3), gains(3));
  EXPECT_NE(gains(3), gains(4));
  options.size_px = 1;
  EXPECT_THROW(RenderStationPhotos(scene, scene.scanner, options), OptionsError);
}

}  // namespace
}  // namespace lidarshop
