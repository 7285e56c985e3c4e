#include "lidarshop/recolor/e57_camera.h"

#include <gtest/gtest.h>

#include "lidarshop/recolor/recolor.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"

namespace lidarshop {
namespace {

// A scan and its photo stored in one E57 file as a pinhole entry: recolouring from the entry's own pose and
// intrinsics gives what the true camera gives.
TEST(E57Camera, RecoloursFromAStoredPinholeEntry) {
  const SceneDescription scene = test_scenes::MakeRecolorScene(false, 120, 180);
  Scan scan = test_scenes::ScanScene(scene);
  const PinholeCamera camera = CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 320, 240, 70);
  E57Image entry;
  entry.name = "beside";
  entry.projection = "pinhole";
  entry.image = RenderPhoto(scene, camera).image;
  entry.pixel_width_m = entry.pixel_height_m = 5e-6;
  entry.focal_length_m = camera.fx_px * 5e-6;
  entry.principal_x_px = camera.cx_px;
  entry.principal_y_px = camera.cy_px;
  entry.world_from_camera = camera.world_from_camera;
  const E57File file = ReadE57Bytes(EncodeE57({scan}, {entry}, {}), "photo.e57");
  ASSERT_EQ(file.images.size(), 1u);
  PinholeCamera stored;
  std::string why;
  ASSERT_TRUE(CameraFromE57Image(file.images[0], &stored, &why)) << why;
  EXPECT_NEAR(stored.fx_px, camera.fx_px, 1e-9);
  EXPECT_LT((stored.world_from_camera - camera.world_from_camera).norm(), 1e-9);
  const RecolorResult from_entry = RecolorScan(file.scans[0], file.images[0].image, stored);
  const RecolorResult from_truth = RecolorScan(file.scans[0], entry.image, camera);
  EXPECT_GT(from_entry.recolored_count, 1000);
  EXPECT_EQ(cv::countNonZero(from_entry.recolored != from_truth.recolored), 0);

  E57Image visual = file.images[0];
  visual.projection = "visual";
  EXPECT_FALSE(CameraFromE57Image(visual, &stored, &why));
  EXPECT_NE(why.find("not a pinhole"), std::string::npos);
  E57Image no_focal = file.images[0];
  no_focal.focal_length_m = 0;
  EXPECT_FALSE(CameraFromE57Image(no_focal, &stored, &why));
}

}  // namespace
}  // namespace lidarshop
