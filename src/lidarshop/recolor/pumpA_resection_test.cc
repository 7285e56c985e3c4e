// The camera of pumpA's own photo from the stored correspondences (data/recolor/pumpA_correspondences.json) and
// the focal length from the photo's EXIF (data/recolor/pumpA_intrinsics_exif.json): a regression guard on the
// picks and on ResectWithIntrinsics with real data (bench/results/recolor.md, pumpA). Reads the shared data
// (../shared/data beside the checkout), like the other real-data tests.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/resection.h"

namespace lidarshop {
namespace {

const std::string kScan = LIDARSHOP_SHARED_DATA_DIR "/e57/pumpA.e57";
const std::string kPairs = LIDARSHOP_SOURCE_DIR "/data/recolor/pumpA_correspondences.json";
const std::string kIntrinsics = LIDARSHOP_SOURCE_DIR "/data/recolor/pumpA_intrinsics_exif.json";

struct PumpA {
  Correspondences pairs;
  PinholeCamera intrinsics;
  ResectionOptions options;
};

PumpA LoadPumpA() {
  const ScanFile file = ReadScanFile(kScan);
  EXPECT_EQ(file.scans.size(), 1u);
  PumpA pump;
  pump.pairs = ReadCorrespondences(kPairs, &file.scans.at(0));
  pump.intrinsics = ReadCameraJson(kIntrinsics);
  pump.options.width_px = 3072;
  pump.options.height_px = 2304;
  pump.options.ransac_threshold_px = 40;  // as in bench/results/recolor.md
  return pump;
}

TEST(PumpAResection, StoredPairsGiveTheMeasuredCamera) {
  const PumpA pump = LoadPumpA();
  ASSERT_GE(pump.pairs.pixel_point.size(), 15u);
  EXPECT_EQ(pump.intrinsics.fx_px, 3200);
  const ResectionResult result = ResectWithIntrinsics(pump.pairs.pixel_point, pump.intrinsics, pump.options);
  // Measured 2026-11-25: 16 of 16 inliers, 6.31 px RMS, largest error 11.1 px (the tank's silhouettes).
  EXPECT_EQ(result.num_inliers, static_cast<int>(pump.pairs.pixel_point.size()));
  EXPECT_LT(result.rms_px, 7.5);
  for (double error : result.reprojection_error_px) EXPECT_LT(error, 15.0);
  // The pose: 9.7 m from the scanner, 0.37 m below its centre (1.5 m above the floor at z = -1.84 m):
  // a hand-held photo from the far side of the pumps.
  const Eigen::Vector3d centre = result.camera.world_from_camera.topRightCorner<3, 1>();
  EXPECT_NEAR(centre.norm(), 9.7, 0.5);
  EXPECT_NEAR(centre.z(), -0.37, 0.2);
}

TEST(PumpAResection, PairsPreferTheExifFocalLength) {
  // Not only the EXIF says 3200 px: with the focal length swept, the pairs' RMS is lowest near it.
  const PumpA pump = LoadPumpA();
  auto rms_with_focal = [&](double focal_px) {
    PinholeCamera intrinsics = pump.intrinsics;
    intrinsics.fx_px = intrinsics.fy_px = focal_px;
    return ResectWithIntrinsics(pump.pairs.pixel_point, intrinsics, pump.options).rms_px;
  };
  const double at_exif = rms_with_focal(3200);
  EXPECT_LT(at_exif, rms_with_focal(2800));
  EXPECT_LT(at_exif, rms_with_focal(3600));
}

}  // namespace
}  // namespace lidarshop
