#include "lidarshop/scan/scan.h"

#include <gtest/gtest.h>

#include "lidarshop/scan/scan_window.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

TEST(ScanTest, DirectionConventions) {
  // θ = 0 looks forward (+y), θ = +π/2 looks right (+x), φ = +π/2 looks up (+z).
  EXPECT_TRUE(DirectionFromAngles(0, 0).isApprox(Eigen::Vector3f(0, 1, 0)));
  EXPECT_TRUE(DirectionFromAngles(M_PI / 2, 0).isApprox(Eigen::Vector3f(1, 0, 0), 1e-6f));
  EXPECT_NEAR(DirectionFromAngles(0.3, M_PI / 2).z(), 1.0f, 1e-6f);
  const Eigen::Vector3f direction = DirectionFromAngles(-0.7, 0.2);
  EXPECT_NEAR(AzimuthOf(direction), -0.7, 1e-6);
  EXPECT_NEAR(ElevationOf(direction), 0.2, 1e-6);
}

TEST(ScanTest, UniformGridPutsHighestElevationInRowZero) {
  const ScanGrid grid = UniformGrid(3, 4, -0.5, 0.5, -0.2, 0.2);
  EXPECT_DOUBLE_EQ(grid.elevation_rad.front(), 0.2);
  EXPECT_DOUBLE_EQ(grid.elevation_rad.back(), -0.2);
  EXPECT_DOUBLE_EQ(grid.azimuth_rad.front(), -0.5);
  EXPECT_DOUBLE_EQ(grid.azimuth_rad.back(), 0.5);
  const cv::Mat directions = DirectionsFromGrid(grid);
  EXPECT_GT(directions.at<cv::Vec3f>(0, 0)[2], 0.0f);
  EXPECT_LT(directions.at<cv::Vec3f>(2, 0)[0], 0.0f);
}

TEST(ScanTest, WrapAngleAndTheGridReadOffTheDirections) {
  EXPECT_NEAR(WrapAngle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(WrapAngle(-3 * M_PI / 2), M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(WrapAngle(M_PI), -M_PI);  // [-π, π)
  EXPECT_DOUBLE_EQ(WrapAngle(0.25), 0.25);
  Scan scan = MakeScan(3, 4);
  const ScanGrid grid = UniformGrid(3, 4, -0.5, 0.5, -0.2, 0.2);
  scan.direction = DirectionsFromGrid(grid);
  scan.grid = grid;
  EXPECT_EQ(GridOf(scan).azimuth_rad, grid.azimuth_rad);  // the scan's own grid when it matches
  scan.grid = {};
  // The middle row has no direction in column 1: that column's azimuth comes from the next row out.
  scan.direction.at<cv::Vec3f>(1, 1) = cv::Vec3f(0, 0, 0);
  const ScanGrid read = GridOf(scan);
  ASSERT_EQ(read.azimuth_rad.size(), 4u);
  ASSERT_EQ(read.elevation_rad.size(), 3u);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(read.azimuth_rad[c], grid.azimuth_rad[c], 1e-6);
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(read.elevation_rad[r], grid.elevation_rad[r], 1e-6);
  EXPECT_FALSE(read.fitted);
  // A column without any direction.
  for (int r = 0; r < 3; ++r) scan.direction.at<cv::Vec3f>(r, 2) = cv::Vec3f(0, 0, 0);
  scan.name = "s";
  try {
    GridOf(scan);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scan 's': column 2 has no ray direction"), std::string::npos)
        << e.what();
  }
}

TEST(ScanTest, WithRangeKeepsRaysAndMarksSynthesized) {
  Scan scan = MakeScan(2, 2);
  scan.direction = DirectionsFromGrid(UniformGrid(2, 2, -0.1, 0.1, -0.1, 0.1));
  scan.valid.at<uint8_t>(0, 0) = kValid;
  scan.range.at<float>(0, 0) = 2.0f;
  scan.point.at<cv::Vec3f>(0, 0) = cv::Vec3f(0, 2, 0);  // a measured point off the nominal direction
  cv::Mat range(2, 2, CV_32F, cv::Scalar(0));
  range.at<float>(0, 0) = 3.0f;
  range.at<float>(1, 1) = 5.0f;
  cv::Mat mark(2, 2, CV_8U, cv::Scalar(0));
  mark.at<uint8_t>(1, 1) = 255;
  const Scan result = WithRange(scan, range, mark);
  EXPECT_EQ(result.point.at<cv::Vec3f>(0, 0), cv::Vec3f(0, 3, 0));
  const cv::Vec3f filled = result.point.at<cv::Vec3f>(1, 1);
  const cv::Vec3f ray = scan.direction.at<cv::Vec3f>(1, 1);
  EXPECT_NEAR(cv::norm(filled - ray * 5.0f), 0.0, 1e-5);
  EXPECT_EQ(result.synthesized.at<uint8_t>(1, 1), 255);
  EXPECT_EQ(result.synthesized.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(result.CountValid(), 2);
  EXPECT_EQ(scan.CountValid(), 1);  // the input is untouched
}

TEST(ScanTest, IntensityIsAnOptionalChannel) {
  Scan scan = MakeScan(2, 3, /*with_color=*/false, /*with_intensity=*/false);
  EXPECT_FALSE(scan.has_intensity());
  EXPECT_NO_THROW(CheckScan(scan));
  EXPECT_EQ(ChannelNames(scan), (std::vector<std::string>{"xyz", "range", "valid", "direction"}));
  scan.valid.at<uint8_t>(0, 1) = kValid;
  scan.point.at<cv::Vec3f>(0, 1) = cv::Vec3f(0, 2, 0);
  scan.range.at<float>(0, 1) = 2;
  const PointCloud cloud = ToPointCloud(scan);
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_TRUE(cloud.intensities.empty());  // not invented
  EXPECT_EQ(RgbdImage(scan).at<cv::Vec4f>(0, 1), cv::Vec4f(0, 0, 0, 2));
  const Scan masked = MaskScan(scan, cv::Mat(2, 3, CV_8U, cv::Scalar(0)));
  EXPECT_FALSE(masked.has_intensity());
  EXPECT_EQ(masked.CountValid(), 0);
  EXPECT_FALSE(Clone(scan).has_intensity());
  EXPECT_FALSE(WithRange(scan, scan.range).has_intensity());
  // The default keeps the intensity channel (0.5, the no-information value) for scanners that measure it.
  const Scan with = MakeScan(2, 3);
  ASSERT_TRUE(with.has_intensity());
  EXPECT_EQ(with.intensity.at<float>(1, 2), 0.5f);
  EXPECT_EQ(ChannelNames(with),
            (std::vector<std::string>{"xyz", "range", "intensity", "valid", "direction"}));
  // A wrongly typed intensity is still a programming error.
  Scan bad = with;
  bad.intensity = cv::Mat(2, 3, CV_8U, cv::Scalar(0));
  EXPECT_THROW(CheckScan(bad), std::logic_error);
}

TEST(ScanTest, MaskScanClearsDroppedCellsAndKeepsDirections) {
  Scan scan = MakeScan(2, 2, /*with_color=*/true);
  scan.direction = DirectionsFromGrid(UniformGrid(2, 2, -0.1, 0.1, -0.1, 0.1));
  scan.label = cv::Mat(2, 2, CV_32S, cv::Scalar(3));
  scan.synthesized = cv::Mat(2, 2, CV_8U, cv::Scalar(kValid));
  scan.world_from_scanner(1, 3) = 4.0;
  for (int c = 0; c < 4; ++c) {
    const int row = c / 2, col = c % 2;
    scan.valid.at<uint8_t>(row, col) = kValid;
    scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * (2.0f + c);
    scan.range.at<float>(row, col) = 2.0f + c;
    scan.intensity.at<float>(row, col) = 0.1f * c;
    scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(10, 20, 30);
  }
  cv::Mat keep(2, 2, CV_8U, cv::Scalar(0));
  keep.at<uint8_t>(0, 1) = 255;
  const Scan masked = MaskScan(scan, keep);
  EXPECT_EQ(masked.CountValid(), 1);
  EXPECT_EQ(masked.valid.at<uint8_t>(0, 1), kValid);
  EXPECT_EQ(masked.range.at<float>(0, 1), 3.0f);
  EXPECT_EQ(masked.color.at<cv::Vec3b>(0, 1), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(masked.valid.at<uint8_t>(1, 0), 0);
  EXPECT_EQ(masked.range.at<float>(1, 0), 0.0f);
  EXPECT_EQ(masked.point.at<cv::Vec3f>(1, 0), cv::Vec3f(0, 0, 0));
  EXPECT_EQ(masked.intensity.at<float>(1, 0), 0.5f);
  EXPECT_EQ(masked.color.at<cv::Vec3b>(1, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(masked.label.at<int32_t>(1, 0), kNoLabel);
  EXPECT_EQ(masked.synthesized.at<uint8_t>(1, 0), 0);
  EXPECT_EQ(masked.synthesized.at<uint8_t>(0, 1), kValid);
  EXPECT_EQ(cv::norm(masked.direction, scan.direction, cv::NORM_INF), 0.0);  // every ray kept
  EXPECT_EQ(masked.world_from_scanner, scan.world_from_scanner);
  EXPECT_EQ(scan.CountValid(), 4);  // the input is untouched
  EXPECT_THROW(MaskScan(scan, cv::Mat(3, 2, CV_8U, cv::Scalar(0))), std::logic_error);
}

TEST(ScanTest, ToPointCloudInWorldFrame) {
  Scan scan = MakeScan(1, 1, /*with_color=*/true);
  scan.valid.at<uint8_t>(0, 0) = kValid;
  scan.point.at<cv::Vec3f>(0, 0) = cv::Vec3f(1, 2, 3);
  scan.range.at<float>(0, 0) = std::sqrt(14.0f);
  scan.world_from_scanner(0, 3) = 10.0;
  const PointCloud cloud = ToPointCloud(scan, /*world=*/true);
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_TRUE(cloud.points[0].isApprox(Eigen::Vector3f(11, 2, 3)));
  EXPECT_EQ(cloud.colors.size(), 1u);
}

TEST(ScanTest, LabelImage16MarksNoReturnAndMissingLabels) {
  Scan scan = MakeScan(1, 3);
  EXPECT_THROW(LabelImage16(scan), std::logic_error);  // no label channel
  scan.label = cv::Mat(1, 3, CV_32S, cv::Scalar(kNoLabel));
  scan.valid.at<uint8_t>(0, 0) = kValid;
  scan.label.at<int32_t>(0, 0) = 7;
  scan.valid.at<uint8_t>(0, 1) = kValid;  // a return without a label
  scan.label.at<int32_t>(0, 2) = 4;       // a label without a return
  const cv::Mat labels = LabelImage16(scan);
  ASSERT_EQ(labels.type(), CV_16U);
  EXPECT_EQ(labels.at<uint16_t>(0, 0), 7);
  EXPECT_EQ(labels.at<uint16_t>(0, 1), kNoReturnLabel16);
  EXPECT_EQ(labels.at<uint16_t>(0, 2), kNoReturnLabel16);
}

TEST(Scan, CropThenPasteGivesTheScanBack) {
  Scan scan = MakeScan(6, 8, /*with_color=*/true);
  scan.grid = UniformGrid(6, 8, -0.4, 0.4, -0.3, 0.3);
  scan.direction = DirectionsFromGrid(scan.grid);
  for (int i = 0; i < 48; ++i) {
    scan.range.at<float>(i / 8, i % 8) = 1.0f + i;
    scan.valid.at<uint8_t>(i / 8, i % 8) = i % 5 ? kValid : 0;
  }
  scan.label = cv::Mat(6, 8, CV_32S, cv::Scalar(3));
  const cv::Rect window(2, 1, 4, 3);
  Scan part = CropScan(scan, window);
  ASSERT_EQ(part.rows, 3);
  ASSERT_EQ(part.cols, 4);
  EXPECT_EQ(part.range.at<float>(0, 0), scan.range.at<float>(1, 2));
  EXPECT_EQ(part.grid.azimuth_rad,
            std::vector<double>(scan.grid.azimuth_rad.begin() + 2, scan.grid.azimuth_rad.begin() + 6));
  EXPECT_EQ(part.grid.elevation_rad[0], scan.grid.elevation_rad[1]);
  EXPECT_TRUE(part.intensity.data != scan.intensity.data);  // a copy, not a view of the input
  // An edit of the part, pasted back: only the window changes; a channel only the part has is added.
  part.range.setTo(100.0f);
  part.synthesized = cv::Mat(3, 4, CV_8U, cv::Scalar(1));
  Scan whole = Clone(scan);
  PasteScan(part, window, &whole);
  EXPECT_EQ(cv::countNonZero(whole.range == 100.0f), 12);
  EXPECT_EQ(whole.range.at<float>(0, 0), scan.range.at<float>(0, 0));
  ASSERT_FALSE(whole.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(whole.synthesized), 12);
  EXPECT_EQ(cv::norm(whole.label, scan.label, cv::NORM_INF), 0.0);
  EXPECT_THROW(CropScan(scan, cv::Rect(6, 0, 4, 2)), std::logic_error);
  EXPECT_THROW(PasteScan(part, cv::Rect(0, 0, 2, 2), &whole), std::logic_error);
}

// 6 x 8 rays on a regular grid with colour, a range per cell (1, 2, ... 48 m) and a GPS-time attribute.
Scan MakeGriddedScan() {
  Scan scan = MakeScan(6, 8, /*with_color=*/true);
  scan.grid = UniformGrid(6, 8, -0.4, 0.4, -0.3, 0.3);
  scan.direction = DirectionsFromGrid(scan.grid);
  for (int i = 0; i < 48; ++i) scan.range.at<float>(i / 8, i % 8) = 1.0f + i;
  scan.attributes["gps_time"] = cv::Mat(6, 8, CV_64F, cv::Scalar(2.5));
  return scan;
}

TEST(Scan, ACropViewHasTheCropsCellsInTheScansOwnBuffers) {
  const Scan scan = MakeGriddedScan();
  const cv::Rect window(2, 1, 4, 3);
  const Scan copy = CropScan(scan, window);
  const Scan view = CropScanView(scan, window);
  ASSERT_EQ(view.rows, 3);
  ASSERT_EQ(view.cols, 4);
  EXPECT_EQ(view.grid.azimuth_rad, copy.grid.azimuth_rad);
  EXPECT_EQ(view.grid.elevation_rad, copy.grid.elevation_rad);
  EXPECT_EQ(cv::norm(view.range, copy.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(view.direction.reshape(1), copy.direction.reshape(1), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(view.attributes.at("gps_time"), copy.attributes.at("gps_time"), cv::NORM_INF), 0.0);
  // No copy: the view's first cell is the scan's cell (1, 2), and its rows are the scan's rows.
  EXPECT_EQ(view.range.ptr<float>(0), scan.range.ptr<float>(1) + 2);
  EXPECT_EQ(view.color.ptr<cv::Vec3b>(2), scan.color.ptr<cv::Vec3b>(3) + 2);
  EXPECT_FALSE(view.range.isContinuous());
  EXPECT_THROW(CropScanView(scan, cv::Rect(6, 0, 4, 2)), std::logic_error);
}

// Copy on write per channel: the channels the part changes are new buffers holding PasteScan's result, the
// others stay the scan's; the scan the copy came from is never written.
TEST(Scan, PasteCopyOnWriteSharesTheChannelsThePartLeavesAsTheyWere) {
  const Scan scan = MakeGriddedScan();
  const Scan before = Clone(scan);
  const cv::Rect window(2, 1, 4, 3);
  Scan part = CropScan(scan, window);
  part.range.setTo(7.0f);
  part.color.setTo(cv::Scalar(1, 2, 3));
  part.synthesized = cv::Mat(3, 4, CV_8U, cv::Scalar(1));  // a channel the scan does not have
  Scan shared = scan;                                      // shallow, as a snapshot kept for undo
  PasteScanCopyOnWrite(part, window, &shared);
  Scan expected = Clone(scan);
  PasteScan(part, window, &expected);
  EXPECT_EQ(cv::norm(shared.range, expected.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(shared.color, expected.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(shared.synthesized, expected.synthesized, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(shared.direction.reshape(1), expected.direction.reshape(1), cv::NORM_INF), 0.0);
  // Changed: new buffers; unchanged: the scan's own.
  EXPECT_NE(shared.range.data, scan.range.data);
  EXPECT_NE(shared.color.data, scan.color.data);
  EXPECT_EQ(shared.direction.data, scan.direction.data);
  EXPECT_EQ(shared.point.data, scan.point.data);
  EXPECT_EQ(shared.attributes.at("gps_time").data, scan.attributes.at("gps_time").data);
  // The scan itself is as it was.
  EXPECT_EQ(cv::norm(scan.range, before.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(scan.color, before.color, cv::NORM_INF), 0.0);
  EXPECT_TRUE(scan.synthesized.empty());
  EXPECT_THROW(PasteScanCopyOnWrite(part, cv::Rect(6, 0, 4, 3), &shared), std::logic_error);
}

}  // namespace
}  // namespace lidarshop
