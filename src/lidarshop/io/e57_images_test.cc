// images2D written by WriteE57 (the photos recolouring uses): photos survive E57 -> E57 bit-exact.
#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::kE57Dir;

TEST(E57Images, PumpAPhotoSurvivesARoundTrip) {
  const E57File file = ReadE57(kE57Dir + "pumpA.e57");
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

// One entry of each representation with every field set, a mask and a scan it belongs to: written and read
// back, every field is equal and the blobs are byte for byte the same.
TEST(E57Images, EveryRepresentationRoundTrips) {
  const auto photo = [](int rows, int cols, int seed) {
    cv::Mat rgb(rows, cols, CV_8UC3);
    cv::RNG random(seed);
    random.fill(rgb, cv::RNG::UNIFORM, 0, 256);
    return rgb;
  };
  std::vector<E57Image> images(4);
  images[0].projection = "pinhole";
  images[0].focal_length_m = 0.0123;
  images[0].pixel_width_m = 3.1e-6;
  images[0].pixel_height_m = 3.3e-6;
  images[0].principal_x_px = 20.25;
  images[0].principal_y_px = 14.5;
  images[1].projection = "spherical";
  images[1].pixel_width_rad = 2 * M_PI / 40;
  images[1].pixel_height_rad = M_PI / 20;
  // The reader keeps pixelWidth / pixelHeight as stored in pixel_width_m / pixel_height_m too.
  images[1].pixel_width_m = images[1].pixel_width_rad;
  images[1].pixel_height_m = images[1].pixel_height_rad;
  images[2].projection = "cylindrical";
  images[2].pixel_width_rad = 2 * M_PI / 40;
  images[2].pixel_height_m = 0.0125;
  images[2].radius_m = 0.75;
  images[2].pixel_width_m = images[2].pixel_width_rad;
  images[2].principal_y_px = 11.75;
  images[3].projection = "visual";
  for (size_t i = 0; i < images.size(); ++i) {
    E57Image& image = images[i];
    image.name = "photo " + std::to_string(i);
    image.description = "the " + image.projection + " one";
    image.guid = "{guid-" + std::to_string(i) + "}";
    image.world_from_camera = ComposeTransform({0.1 * i, -2.0, 1.65}, {3.0 * i, -1, 40});
    image.image = photo(20, 40, static_cast<int>(i));
    image.associated_scan = i % 2 == 0 ? 0 : -1;
    // Stored bytes (any bytes: the writer copies them) for the mask.
    image.mask_encoded = {0x89, 'P', 'N', 'G', static_cast<uint8_t>(i), 1, 2, 3};
  }
  const std::vector<Scan> scans = ReadE57(kE57Dir + "tinyCartesianFloatRgb.e57").scans;
  ASSERT_EQ(scans.size(), 1u);
  const E57File first = ReadE57Bytes(EncodeE57(scans, images, {}), "all.e57");
  ASSERT_EQ(first.images.size(), 4u);
  // Written once more from what was read: the blobs (PNG-encoded on the first write) survive unchanged.
  const E57File back = ReadE57Bytes(EncodeE57(first.scans, first.images, {}), "again.e57");
  ASSERT_EQ(back.images.size(), 4u);
  for (size_t i = 0; i < images.size(); ++i) {
    SCOPED_TRACE(images[i].projection);
    const E57Image& a = images[i];
    for (const E57Image* b : {&first.images[i], &back.images[i]}) {
      EXPECT_EQ(b->name, a.name);
      EXPECT_EQ(b->projection, a.projection);
      EXPECT_EQ(b->description, a.description);
      EXPECT_EQ(b->guid, a.guid);
      EXPECT_EQ(b->associated_scan, a.associated_scan);
      EXPECT_EQ(b->width_px, 40);
      EXPECT_EQ(b->height_px, 20);
      EXPECT_EQ(b->focal_length_m, a.focal_length_m);
      EXPECT_EQ(b->pixel_width_m, a.pixel_width_m);
      EXPECT_EQ(b->pixel_height_m, a.pixel_height_m);
      EXPECT_EQ(b->principal_x_px, a.principal_x_px);
      EXPECT_EQ(b->principal_y_px, a.principal_y_px);
      EXPECT_EQ(b->pixel_width_rad, a.pixel_width_rad);
      EXPECT_EQ(b->pixel_height_rad, a.pixel_height_rad);
      EXPECT_EQ(b->radius_m, a.radius_m);
      EXPECT_LT((b->world_from_camera - a.world_from_camera).norm(), 1e-12);
      EXPECT_EQ(b->mask_encoded, a.mask_encoded);
      EXPECT_EQ(b->encoding, "png");
      EXPECT_EQ(cv::norm(b->image, a.image, cv::NORM_INF), 0);
    }
    EXPECT_EQ(back.images[i].encoded, first.images[i].encoded);
  }
}

// Cameras of each model E57 holds go into an images2D entry and come back as the same camera.
TEST(E57Images, CamerasRoundTripThroughTheirEntries) {
  std::vector<Camera> cameras;
  PinholeCamera pinhole;
  pinhole.width_px = 40, pinhole.height_px = 30;
  pinhole.fx_px = 35, pinhole.fy_px = 36, pinhole.cx_px = 20.5, pinhole.cy_px = 14.75;
  cameras.push_back(CameraFromPinhole(pinhole));
  cameras.push_back(SphericalPanorama(20, Eigen::Matrix4d::Identity()));
  Camera cylinder;
  cylinder.model = CameraModel::kCylindrical;
  cylinder.pinhole.width_px = 40, cylinder.pinhole.height_px = 30;
  cylinder.pixel_width_rad = 0.05, cylinder.pixel_height_m = 0.02, cylinder.radius_m = 0.6;
  cylinder.principal_y_px = 13;
  cameras.push_back(cylinder);
  for (Camera camera : cameras) {
    SCOPED_TRACE(CameraModelName(camera.model));
    camera.world_from_camera = ComposeTransform({1, 2, 3}, {10, 20, 30});
    const cv::Mat rgb(camera.height_px(), camera.width_px(), CV_8UC3, cv::Scalar(1, 2, 3));
    const E57File file = ReadE57Bytes(EncodeE57({}, {E57ImageOfCamera(camera, rgb, "c")}, {}), "cams.e57");
    ASSERT_EQ(file.images.size(), 1u);
    EXPECT_EQ(E57ImageModel(file.images[0]), CameraModelName(camera.model));
    Camera back;
    std::string why;
    ASSERT_TRUE(CameraModelOfE57Image(file.images[0], &back, &why)) << why;
    EXPECT_EQ(back.model, camera.model);
    EXPECT_EQ(back.width_px(), camera.width_px());
    EXPECT_NEAR(back.pinhole.fx_px, camera.pinhole.fx_px, 1e-12 * camera.pinhole.fx_px);
    EXPECT_NEAR(back.pinhole.fy_px, camera.pinhole.fy_px, 1e-12 * camera.pinhole.fy_px);
    EXPECT_EQ(back.pinhole.cx_px, camera.pinhole.cx_px);
    EXPECT_EQ(back.pinhole.cy_px, camera.pinhole.cy_px);
    EXPECT_EQ(back.pixel_width_rad, camera.pixel_width_rad);
    EXPECT_EQ(back.pixel_height_rad, camera.pixel_height_rad);
    EXPECT_EQ(back.pixel_height_m, camera.pixel_height_m);
    EXPECT_EQ(back.radius_m, camera.radius_m);
    EXPECT_EQ(back.principal_y_px, camera.principal_y_px);
    EXPECT_LT((back.world_from_camera - camera.world_from_camera).norm(), 1e-12);
  }
  // What E57 cannot hold is refused, naming the field.
  Camera fisheye = cameras[0];
  fisheye.model = CameraModel::kFisheye;
  const cv::Mat rgb(30, 40, CV_8UC3);
  EXPECT_THROW(E57ImageOfCamera(fisheye, rgb, "f"), InputError);
  Camera distorted = cameras[0];
  distorted.pinhole.k1 = 0.1;
  EXPECT_THROW(E57ImageOfCamera(distorted, rgb, "d"), InputError);
  EXPECT_THROW(E57ImageOfCamera(cameras[0], cv::Mat(29, 40, CV_8UC3), "small"), InputError);
  // A visual reference has no model; a cylindrical entry without a radius says so.
  E57Image visual;
  visual.name = "v";
  visual.projection = "visual";
  Camera camera;
  std::string why;
  EXPECT_FALSE(CameraModelOfE57Image(visual, &camera, &why));
  EXPECT_NE(why.find("no camera model"), std::string::npos);
  E57Image no_radius = E57ImageOfCamera(cameras[2], cv::Mat(30, 40, CV_8UC3), "r");
  no_radius.radius_m = 0;
  EXPECT_FALSE(CameraModelOfE57Image(no_radius, &camera, &why));
  EXPECT_NE(why.find("radius"), std::string::npos);
}

// The real files with images read as before, and their entries name their models.
TEST(E57Images, RealFilesListTheirImages) {
  const E57File pump = ReadE57(kE57Dir + "pumpA.e57");
  ASSERT_EQ(pump.images.size(), 1u);
  EXPECT_EQ(E57ImageModel(pump.images[0]), "");
  const E57File tiny = ReadE57(kE57Dir + "tiny_pc_and_images.e57");
  EXPECT_FALSE(tiny.images.empty());
  const E57File distortion =
      ReadE57(LIDARSHOP_SHARED_DATA_DIR "/interop/e57/libe57_PinholeImageWithDistortionParameters.e57");
  ASSERT_FALSE(distortion.images.empty());
  EXPECT_EQ(distortion.images[0].projection, "pinhole");
  EXPECT_EQ(distortion.images[0].description, "JPEG image test 1 - distortion with all parameters specified");
  // Written and read again, each real file's entries keep their fields and bytes.
  for (const E57File* file : {&pump, &tiny, &distortion}) {
    const E57File back = ReadE57Bytes(EncodeE57(*file, {}), "back.e57");
    ASSERT_EQ(back.images.size(), file->images.size());
    for (size_t i = 0; i < back.images.size(); ++i) {
      EXPECT_EQ(back.images[i].projection, file->images[i].projection);
      EXPECT_EQ(back.images[i].encoded, file->images[i].encoded);
      EXPECT_EQ(back.images[i].mask_encoded, file->images[i].mask_encoded);
      EXPECT_EQ(back.images[i].guid, file->images[i].guid);
      EXPECT_EQ(back.images[i].associated_scan, file->images[i].associated_scan);
      EXPECT_EQ(back.images[i].pixel_width_rad, file->images[i].pixel_width_rad);
      EXPECT_EQ(back.images[i].pixel_width_m, file->images[i].pixel_width_m);
    }
  }
}

// A scan read from E57 keeps its entry's guid, sensor and acquisition times (Scan::source_metadata) and the
// writer writes them back: an edited scan saved as E57 is still that scan, of that date.
TEST(E57Images, ScanGuidSensorAndDatesSurviveASave) {
  const E57File pump = ReadE57(kE57Dir + "pumpA.e57");
  ASSERT_EQ(pump.scans[0].source_metadata.count("e57.guid"), 1u);
  EXPECT_EQ(pump.scans[0].source_metadata.at("e57.guid"), "{116B6772-AC46-41B3-B70C-0C63CC671447}");
  const E57File back = ReadE57Bytes(EncodeE57(pump, {}), "back.e57");
  EXPECT_EQ(back.scans[0].source_metadata.at("e57.guid"), "{116B6772-AC46-41B3-B70C-0C63CC671447}");
  ASSERT_EQ(back.images.size(), 1u);
  EXPECT_EQ(back.images[0].encoded, pump.images[0].encoded);
  // Times and sensor: written as E57 DateTime structures and strings, read back to the same text.
  Scan dated = pump.scans[0];
  dated.source_metadata["e57.acquisition_start_gps_s"] = "1234567890.125";
  dated.source_metadata["e57.acquisition_end_gps_s"] = "1234567990.5";
  dated.source_metadata["e57.sensor_vendor"] = "Acme";
  dated.source_metadata.erase("e57.guid");
  const E57File again = ReadE57Bytes(EncodeE57(std::vector<Scan>{dated}, E57WriteOptions{}), "dated.e57");
  EXPECT_EQ(again.scans[0].source_metadata.at("e57.acquisition_start_gps_s"), "1234567890.125");
  EXPECT_EQ(again.scans[0].source_metadata.at("e57.acquisition_end_gps_s"), "1234567990.5");
  EXPECT_EQ(again.scans[0].source_metadata.at("e57.sensor_vendor"), "Acme");
  EXPECT_EQ(again.scans[0].source_metadata.at("e57.guid").rfind("{lidarshop-scan-", 0),
            0u);  // made, as before
  // A time that is not a number (not one lidarshop read) is not written.
  dated.source_metadata["e57.acquisition_start_gps_s"] = "yesterday";
  EXPECT_EQ(ReadE57Bytes(EncodeE57(std::vector<Scan>{dated}, E57WriteOptions{}), "bad.e57")
                .scans[0]
                .source_metadata.count("e57.acquisition_start_gps_s"),
            0u);
}

}  // namespace
}  // namespace lidarshop
