// What writing keeps and drops (convert's report), and that no writer or reader invents an intensity.
#include "lidarshop/io/scan_write_plan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::Contains;
using testing::ElementsAre;
using testing::HasSubstr;
using testing::IsEmpty;
using testing::Not;
using testing_io::TempFolder;

// A 3 x 4 organized scan, every cell a return 2..3 m ahead, with the channels asked for.
Scan SmallScan(bool intensity, bool color, bool label) {
  Scan scan = MakeScan(3, 4, color, intensity);
  scan.grid = UniformGrid(3, 4, -0.2, 0.2, -0.1, 0.1);
  scan.direction = DirectionsFromGrid(scan.grid);
  if (label) scan.label = cv::Mat(3, 4, CV_32S, cv::Scalar(7));
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      const float range = 2.0f + 0.1f * (row * 4 + col);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
      scan.range.at<float>(row, col) = range;
      if (intensity) scan.intensity.at<float>(row, col) = 0.25f;
      if (color) scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(10, 20, 30);
    }
  }
  return scan;
}

TEST(ScanWritePlan, SaysWhatEachFormatDropsAndRenames) {
  const Scan scan = SmallScan(/*intensity=*/true, /*color=*/true, /*label=*/true);
  const ScanWritePlan las = PlanScanWrite("out.las", {scan}, 0, 0);
  EXPECT_THAT(las.channels, ElementsAre("xyz", "intensity", "rgb", "label→classification"));
  ASSERT_EQ(las.dropped.size(), 1u);
  EXPECT_THAT(las.dropped[0], HasSubstr("out.las: the grid (3 rows x 4 columns) and the scanner pose"));
  EXPECT_EQ(WrittenSummary("out.las", {scan}, 0, las),
            "wrote out.las: 1 scan, 12 points, channels xyz intensity rgb label→classification");

  const ScanWritePlan ptx = PlanScanWrite("out.ptx", {scan}, 2, 1);
  EXPECT_THAT(ptx.channels, ElementsAre("xyz", "intensity", "rgb"));
  EXPECT_THAT(ptx.dropped, ElementsAre("out.ptx: labels are not written (PTX has no label field)",
                                       HasSubstr("2 images (E57 images2D) not written: PTX holds no photos"),
                                       HasSubstr("the second returns of 1 scan are not written")));

  const ScanWritePlan ply = PlanScanWrite("out.ply", {scan}, 0, 0);
  EXPECT_THAT(ply.dropped, IsEmpty());
  EXPECT_THAT(ply.channels, ElementsAre("xyz", "intensity", "rgb", "label"));

  const ScanWritePlan e57 = PlanScanWrite("out.e57", {scan}, 3, 0);
  EXPECT_THAT(e57.dropped, ElementsAre(HasSubstr("labels are not written (E57 has no label field)")));
  EXPECT_EQ(WrittenSummary("out.e57", {scan, scan}, 3, e57),
            "wrote out.e57: 2 scans, 24 points, 3 images, channels xyz intensity rgb");

  const ScanWritePlan xyz = PlanScanWrite("out.xyz", {scan}, 0, 0);
  EXPECT_THAT(xyz.dropped, Contains(HasSubstr("labels are not written (XYZ has no label field)")));
  EXPECT_THROW(PlanScanWrite("out.laz", {scan}, 0, 0), InputError);
  EXPECT_THROW(PlanScanWrite("out.txt", {scan}, 0, 0), InputError);
}

TEST(ScanWritePlan, PtxSaysItWritesTheConventionIntensity) {
  const Scan scan = SmallScan(/*intensity=*/false, /*color=*/false, /*label=*/false);
  const ScanWritePlan ptx = PlanScanWrite("out.ptx", {scan}, 0, 0);
  EXPECT_THAT(ptx.channels, ElementsAre("xyz", "intensity=0.5"));
  EXPECT_THAT(ptx.dropped, ElementsAre(HasSubstr("PTX requires an intensity column: written as 0.5")));
  const ScanWritePlan pcd = PlanScanWrite("out.pcd", {scan}, 0, 0);
  EXPECT_THAT(pcd.channels, ElementsAre("xyz"));
  EXPECT_THAT(pcd.dropped, IsEmpty());
}

TEST(ScanWritePlan, ThousandsSeparators) {
  EXPECT_EQ(WithThousandsSeparators(0), "0");
  EXPECT_EQ(WithThousandsSeparators(999), "999");
  EXPECT_EQ(WithThousandsSeparators(1000), "1,000");
  EXPECT_EQ(WithThousandsSeparators(1234567), "1,234,567");
  EXPECT_EQ(WithThousandsSeparators(-45678), "-45,678");
}

TEST(OptionalIntensity, NoFormatInventsAnIntensityAndEveryFormatKeepsOne) {
  TempFolder folder;
  for (const char* extension : {"ply", "pcd", "e57", "las", "xyz", "pts", "ptx"}) {
    const std::string path = folder.File(std::string("scan.") + extension);
    for (bool intensity : {false, true}) {
      const Scan scan = SmallScan(intensity, /*color=*/true, /*label=*/false);
      WriteScanFile(path, {scan});
      const ScanFile back = ReadScanFile(path);
      ASSERT_EQ(back.scans.size(), 1u) << extension;
      const Scan& read = back.scans[0];
      EXPECT_EQ(read.CountValid(), 12) << extension;
      // PTX always holds the column (0.5 when the scan had none): the one format that cannot leave it out.
      const bool expected = intensity || std::string(extension) == "ptx";
      ASSERT_EQ(read.has_intensity(), expected) << extension << " written with intensity " << intensity;
      if (expected) {
        EXPECT_THAT(ChannelNames(read), Contains("intensity")) << extension;
        EXPECT_NEAR(read.intensity.at<float>(0, 0), intensity ? 0.25f : 0.5f, 1e-3) << extension;
      } else {
        EXPECT_THAT(ChannelNames(read), Not(Contains("intensity"))) << extension;
      }
    }
  }
}

}  // namespace
}  // namespace lidarshop
