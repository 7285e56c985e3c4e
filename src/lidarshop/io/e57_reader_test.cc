// Reading the shared E57 files (real and reference test files); expected values come from each file's XML.
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::kE57Dir;

cv::Vec3f PointAt(const Scan& s, int64_t cell) { return s.point.ptr<cv::Vec3f>()[cell]; }

// Every valid point lies inside the cartesianBounds the file's XML states.
void ExpectInsideBounds(const Scan& s, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double tol) {
  for (int64_t c = 0; c < s.num_cells(); ++c) {
    if (!s.valid.ptr<uint8_t>()[c]) continue;
    const cv::Vec3f p = PointAt(s, c);
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(p[k], lo[k] - tol) << "cell " << c;
      ASSERT_LE(p[k], hi[k] + tol) << "cell " << c;
    }
  }
}

TEST(E57Reader, PumpAIsAnOrganizedScanWithPhoto) {
  const E57File f = ReadE57(kE57Dir + "pumpA.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  const Scan& s = f.scans[0];
  CheckScan(s);
  EXPECT_EQ(s.name, "pumpA");
  // indexBounds: rowMaximum 1073, columnMaximum 344; recordCount 155201 points.
  EXPECT_EQ(s.rows, 1074);
  EXPECT_EQ(s.cols, 345);
  EXPECT_EQ(s.CountValid(), 155201);
  ASSERT_TRUE(s.has_color());
  // sphericalBounds: rangeMinimum 1.983619, rangeMaximum 5.429336.
  double range_min = 1e9, range_max = 0;
  for (int64_t c = 0; c < s.num_cells(); ++c) {
    if (!s.valid.ptr<uint8_t>()[c]) continue;
    const float r = s.range.ptr<float>()[c];
    range_min = std::min<double>(range_min, r);
    range_max = std::max<double>(range_max, r);
    const float i = s.intensity.ptr<float>()[c];
    ASSERT_GE(i, 0.0f);
    ASSERT_LE(i, 1.0f);
  }
  EXPECT_NEAR(range_min, 1.983619, 1e-4);
  EXPECT_NEAR(range_max, 5.429336, 1e-4);
  // Image orientation: the top quarter of rows looks higher than the bottom quarter (pumpA stores rowIndex 0
  // at the bottom; the reader turns it over).
  auto mean_elevation = [&](int r0, int r1) {
    double sum = 0;
    int64_t n = 0;
    for (int r = r0; r < r1; ++r) {
      for (int c = 0; c < s.cols; ++c) {
        if (!s.valid.at<uint8_t>(r, c)) continue;
        const cv::Vec3f p = s.point.at<cv::Vec3f>(r, c);
        sum += ElevationOf(Eigen::Vector3f(p[0], p[1], p[2]));
        ++n;
      }
    }
    return sum / std::max<int64_t>(n, 1);
  };
  EXPECT_GT(mean_elevation(0, s.rows / 4), mean_elevation(3 * s.rows / 4, s.rows) + 0.5);
  // Every cell has a unit direction (no-return cells from the fitted grid).
  const cv::Mat rays = DirectionImage(s);
  for (int64_t c = 0; c < s.num_cells(); ++c) {
    ASSERT_NEAR(cv::norm(rays.ptr<cv::Vec3f>()[c]), 1.0, 1e-4) << "cell " << c;
  }
  // images2D: one visual reference JPEG of 3072 x 2304.
  ASSERT_EQ(f.images.size(), 1u);
  EXPECT_EQ(f.images[0].name, "pumpVisual");
  EXPECT_EQ(f.images[0].projection, "visual");
  EXPECT_EQ(f.images[0].image.cols, 3072);
  EXPECT_EQ(f.images[0].image.rows, 2304);
  EXPECT_EQ(f.images[0].image.type(), CV_8UC3);
}

TEST(E57Reader, BunnyFloatIsUnstructured) {
  const E57File f = ReadE57(kE57Dir + "bunnyFloat.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  const Scan& s = f.scans[0];
  EXPECT_EQ(s.rows, 1);
  EXPECT_EQ(s.cols, 30571);  // recordCount
  EXPECT_GT(s.CountValid(), 0);
  EXPECT_FALSE(s.has_color());
  EXPECT_FALSE(s.has_intensity());  // the file has no intensity field: none is invented
  ExpectInsideBounds(s, {-0.094689, 0.040011, -0.061873}, {0.061009, 0.187321, 0.058799}, 1e-6);
}

TEST(E57Reader, CartesianInvalidStates) {
  // Three records, cartesianInvalidState stored as a Float: 0 (valid), 1 (direction only), 2 (invalid).
  const E57File f = ReadE57(kE57Dir + "cartesian_invalid_state_single.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  const Scan& s = f.scans[0];
  ASSERT_EQ(s.num_cells(), 3);
  EXPECT_EQ(s.CountValid(), 1);
  EXPECT_EQ(s.valid.ptr<uint8_t>()[0], kValid);
  // The valid point is the cartesianBounds' maximum corner (-1, -2, -3).
  EXPECT_EQ(PointAt(s, 0), cv::Vec3f(-1, -2, -3));
  EXPECT_EQ(s.valid.ptr<uint8_t>()[1], 0);
  EXPECT_NEAR(cv::norm(DirectionImage(s).ptr<cv::Vec3f>()[1]), 1.0, 1e-6);  // direction only
  EXPECT_EQ(s.valid.ptr<uint8_t>()[2], 0);
  EXPECT_EQ(DirectionImage(s).ptr<cv::Vec3f>()[2], cv::Vec3f(0, 0, 0));  // nothing known
}

TEST(E57Reader, EmptyFilesAreEmpty) {
  const E57File empty = ReadE57(kE57Dir + "empty.e57");
  EXPECT_TRUE(empty.scans.empty());
  EXPECT_TRUE(empty.images.empty());
  const E57File empty_pc = ReadE57(kE57Dir + "empty_pc.e57");
  ASSERT_EQ(empty_pc.scans.size(), 1u);  // one data3D entry with recordCount 0
  EXPECT_EQ(empty_pc.scans[0].num_cells(), 0);
}

TEST(E57Reader, IntensityLimits) {
  for (const char* name : {"integer_intensity.e57", "scaled_integer_intensity.e57"}) {
    SCOPED_TRACE(name);
    const E57File f = ReadE57(kE57Dir + name);
    ASSERT_EQ(f.scans.size(), 1u);
    const Scan& s = f.scans[0];
    ASSERT_EQ(s.num_cells(), 2);  // recordCount 2
    EXPECT_EQ(s.CountValid(), 2);
    // The two records hold the intensityMinimum and intensityMaximum of intensityLimits.
    EXPECT_FLOAT_EQ(s.intensity.ptr<float>()[0], 0.0f);
    EXPECT_FLOAT_EQ(s.intensity.ptr<float>()[1], 1.0f);
  }
  const E57File f = ReadE57(kE57Dir + "float_intensity_without_min_max.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  ASSERT_EQ(f.scans[0].num_cells(), 1);
  EXPECT_EQ(PointAt(f.scans[0], 0), cv::Vec3f(1, 1, 1));  // cartesianBounds 1..1 on every axis
  EXPECT_GE(f.scans[0].intensity.ptr<float>()[0], 0.0f);
  EXPECT_LE(f.scans[0].intensity.ptr<float>()[0], 1.0f);
}

TEST(E57Reader, UnknownFieldsAreIgnored) {
  const E57File f = ReadE57(kE57Dir + "no_ext_namespace.e57");  // a 'classification' field without namespace
  ASSERT_EQ(f.scans.size(), 1u);
  ASSERT_EQ(f.scans[0].num_cells(), 1);
  EXPECT_EQ(f.scans[0].CountValid(), 1);
  EXPECT_EQ(PointAt(f.scans[0], 0), cv::Vec3f(1, 2, 3));  // cartesianBounds (1, 2, 3)
}

TEST(E57Reader, TinyCartesianFloatRgb) {
  const E57File f = ReadE57(kE57Dir + "tinyCartesianFloatRgb.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  const Scan& s = f.scans[0];
  EXPECT_EQ(s.name, "exp2.fls.subsampled");
  EXPECT_EQ(s.num_cells(), 2090);
  EXPECT_EQ(s.CountValid(), 2090);
  ASSERT_TRUE(s.has_color());
  EXPECT_FALSE(s.has_intensity());
  EXPECT_THAT(ChannelNames(s), ::testing::Not(::testing::Contains("intensity")));
  ExpectInsideBounds(s, {-9.77952957, 4.5138793, 295.524689}, {-6.77423811, 7.51546049, 298.532166}, 1e-4);
  // colorLimits 0..255 over 8-bit fields: colours are not all black.
  EXPECT_GT(cv::sum(s.color)[0], 0.0);
}

TEST(E57Reader, ImagesWithRepresentationsAndPose) {
  const E57File f = ReadE57(kE57Dir + "tiny_pc_and_images.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  EXPECT_EQ(f.scans[0].num_cells(), 2);
  ASSERT_EQ(f.images.size(), 4u);
  EXPECT_EQ(f.images[0].projection, "visual");
  EXPECT_EQ(f.images[0].image.size(), cv::Size(100, 100));  // JPEG
  EXPECT_EQ(f.images[1].projection, "spherical");
  EXPECT_EQ(f.images[1].image.size(), cv::Size(100, 100));  // PNG
  EXPECT_NEAR(f.images[1].pixel_width_m, 0.0314, 1e-12);
  // pose: quaternion (w 0.5, x 1) stored unnormalized, translation (1, 2, 3).
  const Eigen::Matrix4d& pose = f.images[1].world_from_camera;
  EXPECT_NEAR(
      (pose.topLeftCorner<3, 3>() * pose.topLeftCorner<3, 3>().transpose() - Eigen::Matrix3d::Identity())
          .norm(),
      0.0, 1e-12);
  EXPECT_NEAR(pose(0, 0), 1.0, 1e-12);  // rotation about x
  EXPECT_NEAR(pose(1, 1), (0.25 - 1.0) / 1.25, 1e-12);
  EXPECT_TRUE((pose.topRightCorner<3, 1>() == Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(f.images[2].projection, "pinhole");
  EXPECT_EQ(f.images[2].focal_length_m, 123.0);
  EXPECT_EQ(f.images[2].pixel_width_m, 0.044);
  EXPECT_EQ(f.images[2].pixel_height_m, 0.033);
  EXPECT_EQ(f.images[2].principal_x_px, 23.0);
  EXPECT_EQ(f.images[2].principal_y_px, 42.0);
  EXPECT_EQ(f.images[2].width_px, 100);
  // The pinhole and cylindrical blobs of this file are zero-filled: kept, empty, with the reason.
  EXPECT_TRUE(f.images[2].image.empty());
  EXPECT_THAT(f.images[2].decode_error, ::testing::HasSubstr("does not decode"));
  EXPECT_EQ(f.images[3].projection, "cylindrical");
  EXPECT_TRUE(f.images[3].image.empty());
}

TEST(E57Reader, SphericalCoordinates) {
  // 360 records; even ones valid (range 1), odd ones direction only (sphericalInvalidState 1).
  const E57File f = ReadE57(kE57Dir + "tiny_spherical.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  const Scan& s = f.scans[0];
  ASSERT_EQ(s.num_cells(), 360);
  EXPECT_EQ(s.CountValid(), 180);
  // Record 0: range 1, azimuth 0, elevation 0 -> E57 x axis.
  EXPECT_EQ(PointAt(s, 0), cv::Vec3f(1, 0, 0));
  // Record 359: direction at azimuth = elevation = 359 * 3.14 / 360 (counter-clockwise from +x, up from xy).
  const double a = 359.0 * (3.14 / 360.0);
  const cv::Vec3f d = DirectionImage(s).ptr<cv::Vec3f>()[359];
  EXPECT_EQ(s.valid.ptr<uint8_t>()[359], 0);
  EXPECT_NEAR(d[0], std::cos(a) * std::cos(a), 1e-6);
  EXPECT_NEAR(d[1], std::cos(a) * std::sin(a), 1e-6);
  EXPECT_NEAR(d[2], std::sin(a), 1e-6);
  for (int64_t c = 0; c < 360; c += 2) ASSERT_NEAR(s.range.ptr<float>()[c], 1.0f, 1e-6f);
}

TEST(E57Reader, CorruptChecksumNamesThePage) {
  try {
    ReadE57(kE57Dir + "corrupt_crc.e57");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("corrupt_crc.e57"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("page 33 (byte offset 33792)"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("checksum mismatch"));
  }
}

TEST(E57Reader, ReadErrorFileFailsWithClearMessage) {
  // All checksums hold, but every one of its 2651 records claims row 0 / column 0 (zeroed data, as written by
  // the read bug this file reproduces) and the prototype has no returnIndex: the grid is contradictory.
  try {
    ReadE57(kE57Dir + "read_error.e57");
    FAIL() << "read_error.e57 was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("read_error.e57"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("both claim row 0, column 0"));
  }
}

TEST(E57Reader, MissingFileAndNotE57) {
  EXPECT_THROW(ReadE57(kE57Dir + "does_not_exist.e57"), InputError);
  EXPECT_THROW(ReadE57(LIDARSHOP_SHARED_DATA_DIR "/SOURCES.md"), InputError);
}

}  // namespace
}  // namespace lidarshop
