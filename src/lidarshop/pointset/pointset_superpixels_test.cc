// Superpixels of a synthetic scan: every superpixel lies (almost) on one object, and bad options are refused.
#include <map>

#include <gtest/gtest.h>

#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Fraction of returned cells whose superpixel's majority object label is their own.
double Purity(const Scan& scan, const cv::Mat& superpixels) {
  std::map<int, std::map<int, int>> counts;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (scan.valid.at<uint8_t>(row, col))
        ++counts[superpixels.at<int32_t>(row, col)][scan.label.at<int32_t>(row, col)];
    }
  }
  int64_t majority = 0, total = 0;
  for (const auto& [superpixel, labels] : counts) {
    int best = 0;
    for (const auto& [label, count] : labels) {
      best = std::max(best, count);
      total += count;
    }
    majority += best;
  }
  return static_cast<double>(majority) / static_cast<double>(total);
}

TEST(SuperpixelsTest, SuperpixelsFollowTheObjects) {
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  for (SuperpixelMethod method : {SuperpixelMethod::kSlic, SuperpixelMethod::kGraph}) {
    int count = 0;
    const cv::Mat labels = ScanSuperpixels(scan, {.method = method}, &count);
    ASSERT_EQ(labels.size(), scan.valid.size());
    EXPECT_GT(count, 5);
    EXPECT_GT(Purity(scan, labels), 0.99) << static_cast<int>(method);
    EXPECT_EQ(cv::countNonZero(labels != ScanSuperpixels(scan, {.method = method})), 0);
  }
  EXPECT_THROW(ScanSuperpixels(scan, {.region_cells = 1}), OptionsError);
}

}  // namespace
}  // namespace lidarshop
