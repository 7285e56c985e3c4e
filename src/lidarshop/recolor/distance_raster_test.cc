#include "lidarshop/recolor/distance_raster.h"

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "lidarshop/recolor/view_cull.h"
#include "lidarshop/recolor/visibility.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop::recolor_internal {
namespace {

struct Agreement {
  int64_t pixels = 0, hit_mismatch = 0, distance_mismatch = 0, back_mismatch = 0;
};

// Where the rasterized buffer and the cast one disagree: a hit in one and none in the other, a distance off by
// more than 1e-4 relative (float rounding of two different exact tests), or the back-facing flag.
Agreement Compare(const DistanceBuffer& raster, const DistanceBuffer& cast) {
  Agreement a;
  for (int r = 0; r < cast.distance.rows; ++r) {
    for (int c = 0; c < cast.distance.cols; ++c) {
      ++a.pixels;
      const float x = raster.distance.at<float>(r, c), y = cast.distance.at<float>(r, c);
      if (std::isfinite(x) != std::isfinite(y)) {
        ++a.hit_mismatch;
        continue;
      }
      if (std::isfinite(x) && std::abs(x - y) > 1e-4f * y) ++a.distance_mismatch;
      if (raster.back_facing.at<uint8_t>(r, c) != cast.back_facing.at<uint8_t>(r, c)) ++a.back_mismatch;
    }
  }
  return a;
}

Camera Offset(const Camera& camera, const Eigen::Vector3d& center) {
  Camera moved = camera;
  moved.world_from_camera.topRightCorner<3, 1>() = center;
  return moved;
}

class DistanceRasterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const SceneDescription scene = test_scenes::MakeRecolorScene(false, 150, 225);
    scan_ = test_scenes::ScanScene(scene);
    occlusion_ = BuildOcclusionScene(scan_, options_);
    cast_scene_.AddMesh(occlusion_.mesh, 0);
    if (!occlusion_.skirts.empty()) cast_scene_.AddMesh(occlusion_.skirts, 1);
    cast_scene_.Commit();
  }

  // The rasterized buffer equals the cast one but on a few pixels through triangle edges, where two exact
  // tests in float may round differently.
  // Returns the triangles the raster left to the cast.
  int64_t ExpectSameAsCast(const Camera& camera, const std::string& what, double scale = 1.0,
                           const RasterOptions& raster_options = {}) {
    const DistanceBuffer cast = CastDistanceBuffer(cast_scene_, camera, scale);
    const DistanceBuffer raster =
        RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, scale, raster_options);
    const Agreement a = Compare(raster, cast);
    int64_t hits = 0;
    for (int r = 0; r < cast.distance.rows; ++r)
      for (int c = 0; c < cast.distance.cols; ++c) hits += std::isfinite(cast.distance.at<float>(r, c));
    std::printf("%s: %lld pixels, %lld hit; differ: hit %lld, distance %lld, back-facing %lld; %lld cast\n",
                what.c_str(), static_cast<long long>(a.pixels), static_cast<long long>(hits),
                static_cast<long long>(a.hit_mismatch), static_cast<long long>(a.distance_mismatch),
                static_cast<long long>(a.back_mismatch), static_cast<long long>(raster.cast_triangles));
    EXPECT_GT(hits, 5000) << what;  // the camera sees the scene
    EXPECT_LE(a.hit_mismatch, a.pixels / 2000) << what;
    EXPECT_LE(a.distance_mismatch, a.pixels / 2000) << what;
    EXPECT_LE(a.back_mismatch, a.pixels / 2000) << what;
    return raster.cast_triangles;
  }

  RecolorOptions options_;
  Scan scan_;
  OcclusionScene occlusion_;
  RaycastScene cast_scene_;
};

TEST_F(DistanceRasterTest, PinholeBesideTheScannerSeesWhatTheRaysSee) {
  ExpectSameAsCast(CameraFromPinhole(CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 400, 300, 75)),
                   "pinhole 1.5 m right");
}

TEST_F(DistanceRasterTest, DistortedPinholeAndAHalfSizeBuffer) {
  PinholeCamera pinhole = CameraLookingAt({-0.8, 0.5, 1.2}, {0, 10, 1.5}, 400, 300, 80);
  pinhole.k1 = -0.12, pinhole.k2 = 0.03, pinhole.p1 = 0.001, pinhole.p2 = -0.0005;
  ExpectSameAsCast(CameraFromPinhole(pinhole), "distorted pinhole", 1.0);
  ExpectSameAsCast(CameraFromPinhole(pinhole), "distorted pinhole, half buffer", 0.5);
}

TEST_F(DistanceRasterTest, SphericalPanoramaAboveTheScanner) {
  ExpectSameAsCast(Offset(SphericalPanorama(300, Eigen::Matrix4d::Identity()), {0, 0, 0.15}),
                   "sphere 0.15 m up");
}

TEST_F(DistanceRasterTest, FisheyeAcrossTheScene) {
  PinholeCamera pinhole = CameraLookingAt({0.4, -0.5, 1.0}, {0, 10, 1.2}, 400, 400, 90);
  Camera fisheye = CameraFromPinhole(pinhole);
  fisheye.model = CameraModel::kFisheye;
  fisheye.pinhole.fx_px = fisheye.pinhole.fy_px = 120;
  fisheye.fisheye_k[0] = 0.02;
  fisheye.world_from_camera = pinhole.world_from_camera;
  ExpectSameAsCast(fisheye, "fisheye");
}

// Triangles the raster cannot bound go to an Embree scene of their own: with every triangle wider than a
// pixel sent there, and with a camera among the scan's points (corners behind it), the buffer is the same.
TEST_F(DistanceRasterTest, TrianglesLeftToTheCastMergeIntoTheBuffer) {
  const Camera camera = CameraFromPinhole(CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 400, 300, 75));
  RasterOptions tiny;
  tiny.max_raster_px = 1;
  EXPECT_GT(ExpectSameAsCast(camera, "pinhole, wide triangles cast", 1.0, tiny), 1000);
  // Inside the scene, a metre before the wall, looking along it: many triangles straddle the image plane
  // (without the view culling, which drops those outside the image's pyramid: then none is left to cast).
  const Camera inside = CameraFromPinhole(CameraLookingAt({0.5, 8.5, 1.0}, {-3, 9.5, 1.0}, 400, 300, 100));
  // With the culling fewer are left (the skirts' walls, 2 m deep behind the pillar and the box, still reach
  // the camera's side of the image plane).
  RasterOptions no_cull;
  no_cull.cull_outside_view = false;
  const int64_t not_culled = ExpectSameAsCast(inside, "pinhole inside the scene, not culled", 1.0, no_cull);
  EXPECT_GT(not_culled, 0);
  EXPECT_LT(ExpectSameAsCast(inside, "pinhole inside the scene"), not_culled);
}

// The view culling (recolor/view_cull.h) changes no pixel: the same buffer, bit for bit, with and without it,
// from the blocks' boxes given or computed here.
TEST_F(DistanceRasterTest, CullingOutsideTheViewChangesNoPixel) {
  PinholeCamera distorted = CameraLookingAt({-0.8, 0.5, 1.2}, {0, 10, 1.5}, 400, 300, 80);
  distorted.k1 = -0.12, distorted.k2 = 0.03, distorted.p1 = 0.001, distorted.p2 = -0.0005;
  const Camera cameras[] = {
      CameraFromPinhole(CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 400, 300, 75)),
      CameraFromPinhole(distorted),
      CameraFromPinhole(CameraLookingAt({0.5, 8.5, 1.0}, {-3, 9.5, 1.0}, 400, 300, 100)),
      CameraFromPinhole(CameraLookingAt({0, 0, 1.6}, {0, 10, 1.6}, 300, 300, 90)),  // a cube face
  };
  RasterOptions no_cull;
  no_cull.cull_outside_view = false;
  const std::vector<Eigen::AlignedBox3f> mesh_boxes = TriangleBlockBoxes(occlusion_.mesh);
  const std::vector<Eigen::AlignedBox3f> skirt_boxes = TriangleBlockBoxes(occlusion_.skirts);
  for (const Camera& camera : cameras) {
    const DistanceBuffer all = RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, 1.0, no_cull);
    const DistanceBuffer culled = RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, 1.0);
    const DistanceBuffer given = RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, 1.0, {},
                                                      {&mesh_boxes, &skirt_boxes});
    EXPECT_GT(cv::countNonZero(all.distance < 1e30), 5000);  // it sees the scene
    for (const DistanceBuffer* b : {&culled, &given}) {
      EXPECT_EQ(cv::norm(all.distance != b->distance, cv::NORM_L1), 0.0);  // +inf == +inf
      EXPECT_EQ(cv::norm(all.back_facing, b->back_facing, cv::NORM_L1), 0.0);
      EXPECT_LE(b->cast_triangles, all.cast_triangles);
    }
  }
}

TEST_F(DistanceRasterTest, SameBufferOnAnyThreadCount) {
  const Camera camera = Offset(SphericalPanorama(200, Eigen::Matrix4d::Identity()), {0.3, -0.2, 0.15});
  DistanceBuffer one;
  {
    const ThreadLimit limit(1);
    one = RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, 1.0);
  }
  const DistanceBuffer two = RasterDistanceBuffer(occlusion_.mesh, occlusion_.skirts, camera, 1.0);
  EXPECT_EQ(cv::norm(one.distance != two.distance, cv::NORM_L1), 0.0);  // +inf == +inf
  EXPECT_EQ(cv::norm(one.back_facing, two.back_facing, cv::NORM_L1), 0.0);
}

}  // namespace
}  // namespace lidarshop::recolor_internal
