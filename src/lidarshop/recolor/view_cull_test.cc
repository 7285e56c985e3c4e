#include "lidarshop/recolor/view_cull.h"

#include <random>

#include <gtest/gtest.h>

#include "lidarshop/geometry/camera.h"

namespace lidarshop::recolor_internal {
namespace {

// Every pixel's ray lies inside the planes, and a point outside them projects outside the image (or not at
// all), for plain and distorted pinholes in any pose.
TEST(ViewCull, PlanesHoldEveryRayOfTheImageAndNothingThatProjectsInside) {
  PinholeCamera plain = CameraLookingAt({1, 2, 1.5}, {4, 8, 1}, 640, 480, 70);
  PinholeCamera distorted = CameraLookingAt({-1, 0, 1}, {-5, 3, 2}, 400, 300, 90);
  distorted.k1 = -0.15, distorted.k2 = 0.04, distorted.p1 = 0.002, distorted.p2 = -0.001;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0, 1), any(-20, 20);
  for (const PinholeCamera& pinhole : {plain, distorted}) {
    const Camera camera = CameraFromPinhole(pinhole);
    const ViewPlanes planes = ImageViewPlanes(camera);
    ASSERT_EQ(planes.count, 4);
    for (int i = 0; i < 20000; ++i) {
      const Eigen::Vector2d pixel(unit(random) * camera.width_px(), unit(random) * camera.height_px());
      const Eigen::Vector3d ray = UnprojectPixel(pinhole, pixel);
      EXPECT_EQ(planes.Outcode((3.7 * ray).cast<float>()), 0) << pixel.transpose();
    }
    int64_t outside = 0, inside_image = 0;
    const Eigen::Matrix3d camera_from_world = camera.world_from_camera.topLeftCorner<3, 3>().transpose();
    for (int i = 0; i < 200000; ++i) {
      const Eigen::Vector3d world(any(random), any(random), any(random) / 4);
      const Eigen::Vector3d in_camera = camera_from_world * (world - camera.center_in_world());
      Eigen::Vector2d pixel;
      const bool projects = ProjectWorldPoint(camera, world, &pixel) && InsideImage(camera, pixel);
      inside_image += projects;
      const bool out = planes.Outcode(in_camera.cast<float>()) != 0;
      outside += out;
      if (out) EXPECT_FALSE(projects) << world.transpose();
      // A box around the point: outside only when the point is.
      const Eigen::AlignedBox3f box(world.cast<float>(), world.cast<float>());
      if (planes.Outside(box)) EXPECT_TRUE(out);
    }
    EXPECT_GT(outside, 100000);  // most of the random points: the test can fail
    EXPECT_GT(inside_image, 1000);
  }
}

TEST(ViewCull, BoxesOutsideOnePlaneOnly) {
  const Camera camera = CameraFromPinhole(CameraLookingAt({0, 0, 0}, {10, 0, 0}, 300, 300, 90));
  const ViewPlanes planes = ImageViewPlanes(camera);
  // Straight ahead, behind, and beside: a box that straddles the view is kept.
  EXPECT_FALSE(planes.Outside(Eigen::AlignedBox3f(Eigen::Vector3f(9, -1, -1), Eigen::Vector3f(11, 1, 1))));
  EXPECT_TRUE(planes.Outside(Eigen::AlignedBox3f(Eigen::Vector3f(-11, -1, -1), Eigen::Vector3f(-9, 1, 1))));
  EXPECT_TRUE(planes.Outside(Eigen::AlignedBox3f(Eigen::Vector3f(1, 8, -1), Eigen::Vector3f(2, 9, 1))));
  EXPECT_FALSE(planes.Outside(Eigen::AlignedBox3f(Eigen::Vector3f(5, 4, -1), Eigen::Vector3f(6, 9, 1))));
  EXPECT_TRUE(planes.Outside(Eigen::AlignedBox3f()));  // empty
  // Panoramas get no planes: nothing is culled.
  EXPECT_EQ(ImageViewPlanes(SphericalPanorama(100, Eigen::Matrix4d::Identity())).count, 0);
}

// A distortion the fixed-point undistortion cannot invert at the corners: no planes, nothing culled.
TEST(ViewCull, NoPlanesWhereTheBorderRaysDoNotProjectBack) {
  PinholeCamera wild = CameraLookingAt({0, 0, 0}, {10, 0, 0}, 400, 300, 120);
  wild.k1 = 2.5, wild.k2 = 3.0;
  EXPECT_EQ(ImageViewPlanes(CameraFromPinhole(wild)).count, 0);
  PinholeCamera ordinary = CameraLookingAt({0, 0, 0}, {10, 0, 0}, 400, 300, 70);
  ordinary.k1 = -0.1;  // an ordinary barrel distortion is bounded
  EXPECT_EQ(ImageViewPlanes(CameraFromPinhole(ordinary)).count, 4);
}

}  // namespace
}  // namespace lidarshop::recolor_internal
