#include "lidarshop/image/colormap.h"

#include <set>

#include <gtest/gtest.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

double Lightness(const cv::Vec3b& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

TEST(ColorMapTest, PerceptualMapsAreMonotoneInLightness) {
  for (ColorMap map : {ColorMap::kViridis, ColorMap::kMagma, ColorMap::kGray}) {
    const std::vector<cv::Vec3b>& table = ColorMapTable(map);
    ASSERT_EQ(table.size(), 256u);
    int increases = 0;
    for (int i = 1; i < 256; ++i) {
      EXPECT_GE(Lightness(table[i]), Lightness(table[i - 1]) - 0.5) << ToString(map) << " at " << i;
      increases += Lightness(table[i]) > Lightness(table[i - 1]);
    }
    EXPECT_GT(increases, 200) << ToString(map);
  }
  // Viridis runs from dark purple to yellow (RGB order).
  const std::vector<cv::Vec3b>& viridis = ColorMapTable(ColorMap::kViridis);
  EXPECT_GT(viridis.front()[2], viridis.front()[1]);  // blue > green at the low end
  EXPECT_GT(viridis.back()[0], 200);                  // red and green high at the top
  EXPECT_GT(viridis.back()[1], 200);
}

TEST(ColorMapTest, ApplyColorMapClampsAndMasks) {
  cv::Mat values = (cv::Mat_<float>(1, 5) << -1.f, 0.f, 0.5f, 1.f, 7.f);
  cv::Mat mask = (cv::Mat_<uint8_t>(1, 5) << 255, 255, 255, 0, 255);
  const ColorScale scale{0.0, 1.0, ColorMap::kViridis, "m"};
  const cv::Mat image = ApplyColorMap(values, mask, scale, cv::Vec3b(1, 2, 3));
  const std::vector<cv::Vec3b>& table = ColorMapTable(ColorMap::kViridis);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), table.front());
  EXPECT_EQ(image.at<cv::Vec3b>(0, 1), table.front());
  EXPECT_EQ(image.at<cv::Vec3b>(0, 3), cv::Vec3b(1, 2, 3));
  EXPECT_EQ(image.at<cv::Vec3b>(0, 4), table.back());
  EXPECT_LT(Lightness(image.at<cv::Vec3b>(0, 1)), Lightness(image.at<cv::Vec3b>(0, 2)));
}

TEST(ColorMapTest, AutoScaleIgnoresStrayValues) {
  cv::Mat values(1, 1000, CV_32F);
  for (int i = 0; i < 1000; ++i) values.at<float>(0, i) = static_cast<float>(i % 100);  // 0..99
  values.at<float>(0, 7) = 1e6f;                                                        // one stray far point
  const ColorScale scale = AutoScale(values, cv::Mat(), ColorMap::kTurbo, "m");
  EXPECT_NEAR(scale.min_value, 1.0, 1.01);
  EXPECT_NEAR(scale.max_value, 98.0, 1.01);
}

TEST(ColorMapTest, LabelColoursAreDistinct) {
  std::set<std::tuple<int, int, int>> colors;
  for (int label = 0; label < 20; ++label) {
    const cv::Vec3b c = LabelColor(label);
    EXPECT_GT(c[0] + c[1] + c[2], 100);  // never (nearly) black
    colors.insert({c[0], c[1], c[2]});
  }
  EXPECT_EQ(colors.size(), 20u);
  EXPECT_EQ(LabelColor(-1), cv::Vec3b(0, 0, 0));
}

TEST(ColorMapTest, LegendSitsBesideTheImage) {
  const cv::Mat image(50, 30, CV_8UC3, cv::Scalar::all(7));
  const cv::Mat bar = ColorScaleBar({0.0, 10.0, ColorMap::kViridis, "m"}, image.rows);
  const cv::Mat combined = BesideLegend(image, bar);
  EXPECT_EQ(combined.cols, image.cols + bar.cols);
  EXPECT_EQ(combined.rows, std::max(image.rows, bar.rows));
  EXPECT_EQ(combined.at<cv::Vec3b>(0, 0), cv::Vec3b(7, 7, 7));
  EXPECT_THROW(ParseEnum<ColorMap>("jet"), OptionsError);
}

}  // namespace
}  // namespace lidarshop
