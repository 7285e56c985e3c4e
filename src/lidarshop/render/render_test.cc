#include "lidarshop/render/render.h"

#include <gtest/gtest.h>

#include "lidarshop/io/ptx.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A PTX scan, 3 columns x 4 rows, whose top row (the last line of each column) has intensity 1 and the rest
// 0.1; the range grows from the bottom row to the top row.
Scan BrightTopScan() {
  std::string text = "3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  for (int col = 0; col < 3; ++col) {
    for (int r = 0; r < 4; ++r) {  // bottom to top
      const double range = 2.0 + r;
      const double azimuth = -0.1 + 0.1 * col, elevation = -0.15 + 0.1 * r;
      const Eigen::Vector3f p = DirectionFromAngles(azimuth, elevation) * range;
      text += fmt::format("{} {} {} {}\n", p.x(), p.y(), p.z(), r == 3 ? 1.0 : 0.1);
    }
  }
  return ParsePtx(text, "bright_top.ptx")[0];
}

double Lightness(const cv::Vec3b& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

TEST(RenderTest, BrightTopRowRendersAtImageRowZero) {
  const Scan scan = BrightTopScan();
  RenderOptions options;
  options.channel = RenderChannel::kIntensity;
  const RenderResult result = RenderScan(scan, options);
  ASSERT_EQ(result.image.rows, 4);
  ASSERT_EQ(result.image.cols, 3);
  for (int col = 0; col < 3; ++col) {
    EXPECT_EQ(result.image.at<cv::Vec3b>(0, col), cv::Vec3b(255, 255, 255));
    for (int row = 1; row < 4; ++row) EXPECT_LT(Lightness(result.image.at<cv::Vec3b>(row, col)), 40);
  }
}

TEST(RenderTest, RangeUsesTheMonotoneMapTopFarthest) {
  const Scan scan = BrightTopScan();
  RenderOptions options;  // range, viridis
  options.min_value = 2.0;
  options.max_value = 5.0;
  const RenderResult result = RenderScan(scan, options);
  ASSERT_TRUE(result.scale.has_value());
  // The top row is the farthest: brightest in viridis; lightness falls row by row.
  for (int row = 1; row < 4; ++row) {
    EXPECT_GT(Lightness(result.image.at<cv::Vec3b>(row - 1, 1)),
              Lightness(result.image.at<cv::Vec3b>(row, 1)));
  }
  options.legend = true;
  const RenderResult with_legend = RenderScan(scan, options);
  EXPECT_GT(with_legend.image.cols, 3 + 50);
  EXPECT_GE(with_legend.image.rows, 4);
}

TEST(RenderTest, ValidLabelsNormalsAndMissingChannels) {
  Scan scan = BrightTopScan();
  scan.valid.at<uint8_t>(1, 1) = 0;
  RenderOptions options;
  options.channel = RenderChannel::kValid;
  const cv::Mat valid = RenderScan(scan, options).image;
  EXPECT_EQ(valid.at<cv::Vec3b>(1, 1), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(valid.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 255, 255));

  options.channel = RenderChannel::kLabels;
  EXPECT_THROW(RenderScan(scan, options), InputError);
  scan.label = cv::Mat(4, 3, CV_32S, cv::Scalar(2));
  scan.label.at<int32_t>(3, 0) = 5;
  const cv::Mat labels = RenderScan(scan, options).image;
  EXPECT_EQ(labels.at<cv::Vec3b>(0, 0), LabelColor(2));
  EXPECT_EQ(labels.at<cv::Vec3b>(3, 0), LabelColor(5));

  options.channel = RenderChannel::kRgb;
  EXPECT_THROW(RenderScan(scan, options), InputError);

  // Estimated normals of a sphere around the scanner point back at it:
  // -direction, i.e. (n + 1) / 2 < 0.5 in y.
  options.channel = RenderChannel::kNormals;
  scan.valid.setTo(kValid);
  scan.point = DirectionImage(scan) * 3.0;
  const cv::Mat normals = EstimateGridNormals(scan);
  const cv::Vec3f n = normals.at<cv::Vec3f>(2, 1);
  EXPECT_LT(n[1], -0.95f);
  EXPECT_LT(RenderScan(scan, options).image.at<cv::Vec3b>(2, 1)[1], 128);
  EXPECT_THROW(ParseEnum<RenderChannel>("depthx"), OptionsError);
}

TEST(RenderTest, IntensityOfAScanWithoutItNamesWhatTheScanHas) {
  Scan scan = BrightTopScan();
  scan.intensity = cv::Mat();
  scan.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(9));
  scan.name = "cloud.pcd";
  RenderOptions options;
  options.channel = RenderChannel::kIntensity;
  try {
    RenderScan(scan, options);
    FAIL() << "rendered an intensity the scan does not have";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "cloud.pcd has no intensity channel; it has: xyz, rgb");
  }
  // Every other channel still renders.
  options.channel = RenderChannel::kRange;
  EXPECT_EQ(RenderScan(scan, options).image.size(), cv::Size(3, 4));
}

}  // namespace
}  // namespace lidarshop
