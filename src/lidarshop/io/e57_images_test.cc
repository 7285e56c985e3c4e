// images2D written by WriteE57 (the photos recolouring uses): photos survive E57 -> E57 bit-exact.
#include <gtest/gtest.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_io.h"

namespace lidarshop {
namespace {

const std::string kDir = LIDARSHOP_SHARED_DATA_DIR "/e57/";

TEST(E57Images, PumpAPhotoSurvivesARoundTrip) {
  const E57File file = ReadE57(kDir + "pumpA.e57");
  ASSERT_EQ(file.images.size(), 1u);
  EXPECT_EQ(file.images[0].encoding, "jpeg");
  const E57File back = ReadE57Bytes(EncodeE57(file.scans, file.images, {}), "round_trip.e57");
  ASSERT_EQ(back.images.size(), 1u);
  const E57Image& a = file.images[0];
  const E57Image& b = back.images[0];
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.projection, "visual");
  EXPECT_EQ(b.encoded, a.encoded);
  EXPECT_EQ(b.width_px, 3072);
  EXPECT_EQ(b.height_px, 2304);
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0);
  ASSERT_EQ(back.scans.size(), 1u);
  EXPECT_EQ(back.scans[0].CountValid(), file.scans[0].CountValid());
}

TEST(E57Images, PinholeIntrinsicsAndPoseAreWrittenAndUndecodedPhotosEncoded) {
  E57Image pinhole;
  pinhole.name = "cam";
  pinhole.projection = "pinhole";
  pinhole.image = cv::Mat(6, 8, CV_8UC3, cv::Scalar(10, 200, 30));
  pinhole.focal_length_m = 0.02;
  pinhole.pixel_width_m = 4e-6;
  pinhole.pixel_height_m = 5e-6;
  pinhole.principal_x_px = 4.5;
  pinhole.principal_y_px = 3.25;
  pinhole.world_from_camera(0, 3) = 1.5;
  pinhole.world_from_camera.topLeftCorner<3, 3>() << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  E57Image nothing;  // no bytes, no image: skipped
  const E57File back = ReadE57Bytes(EncodeE57({}, {pinhole, nothing}, {}), "pinhole.e57");
  ASSERT_EQ(back.images.size(), 1u);
  const E57Image& b = back.images[0];
  EXPECT_EQ(b.projection, "pinhole");
  EXPECT_EQ(b.encoding, "png");
  EXPECT_EQ(b.width_px, 8);
  EXPECT_EQ(b.height_px, 6);
  EXPECT_DOUBLE_EQ(b.focal_length_m, 0.02);
  EXPECT_DOUBLE_EQ(b.pixel_height_m, 5e-6);
  EXPECT_DOUBLE_EQ(b.principal_y_px, 3.25);
  EXPECT_LT((b.world_from_camera - pinhole.world_from_camera).norm(), 1e-12);
  EXPECT_EQ(cv::norm(b.image, pinhole.image, cv::NORM_INF), 0);  // PNG: lossless
}

}  // namespace
}  // namespace lidarshop
