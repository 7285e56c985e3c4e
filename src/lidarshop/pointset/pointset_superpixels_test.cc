// Superpixels of a synthetic scan: every superpixel lies (almost) on one object, and bad options are refused.
#include <map>

#include <gtest/gtest.h>

#include "lidarshop/pointset/quickshift.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

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
  for (SuperpixelMethod method :
       {SuperpixelMethod::kSlic, SuperpixelMethod::kGraph, SuperpixelMethod::kQuickShift}) {
    int count = 0;
    const cv::Mat labels = ScanSuperpixels(scan, {.method = method}, &count);
    ASSERT_EQ(labels.size(), scan.valid.size());
    EXPECT_GT(count, 5);
    EXPECT_GT(Purity(scan, labels), 0.99) << static_cast<int>(method);
    EXPECT_EQ(cv::countNonZero(labels != ScanSuperpixels(scan, {.method = method})), 0);
    EXPECT_EQ(cv::countNonZero((labels < 0) != (scan.valid == 0)), 0) << static_cast<int>(method);
  }
  EXPECT_THROW(ScanSuperpixels(scan, {.region_cells = 1}), OptionsError);
  EXPECT_THROW(ScanSuperpixels(scan, {.quickshift_max_dist = 0}), OptionsError);
}

// Four flat quadrants: one mode each, so exactly four segments on the quadrants; a hole in the mask stays -1.
TEST(QuickShiftTest, FlatRegionsAreOneSegmentEach) {
  cv::Mat features(40, 60, CV_32FC2);
  for (int r = 0; r < 40; ++r) {
    for (int c = 0; c < 60; ++c) {
      features.at<cv::Vec2f>(r, c) = cv::Vec2f(r < 20 ? 0.f : 50.f, c < 30 ? 0.f : 50.f);
    }
  }
  cv::Mat mask(40, 60, CV_8U, cv::Scalar(255));
  mask(cv::Rect(5, 5, 4, 4)).setTo(0);
  int count = 0;
  const cv::Mat labels = QuickShift(features, mask, {.kernel_size = 2.0, .max_dist = 8.0}, &count);
  ASSERT_EQ(count, 4);
  for (int r = 0; r < 40; ++r) {
    for (int c = 0; c < 60; ++c) {
      if (mask.at<uint8_t>(r, c) == 0) {
        EXPECT_EQ(labels.at<int32_t>(r, c), -1);
        continue;
      }
      const int quadrant = (r < 20 ? 0 : 2) + (c < 30 ? 0 : 1);  // roots are numbered in row-major order
      ASSERT_EQ(labels.at<int32_t>(r, c), quadrant) << r << "," << c;
    }
  }
  // A longer link reaches across the 50-unit step: one segment. A shorter one splits flat regions too.
  QuickShift(features, mask, {.kernel_size = 2.0, .max_dist = 80.0}, &count);
  EXPECT_EQ(count, 1);
  QuickShift(features, mask, {.kernel_size = 2.0, .max_dist = 1.0}, &count);
  EXPECT_GT(count, 4);
  // Bad input: refused with an error, not a crash.
  cv::Mat as_bytes;
  features.convertTo(as_bytes, CV_8U);
  EXPECT_THROW(QuickShift(as_bytes, mask, {}), InputError);
  EXPECT_THROW(QuickShift(features, mask(cv::Rect(0, 0, 10, 10)), {}), InputError);
  EXPECT_THROW(QuickShift(features, mask, {.kernel_size = 0.0}), OptionsError);
}

TEST(QuickShiftTest, SameLabelsOnAnyThreadCount) {
  const Scan scan = test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene());
  const SuperpixelOptions options{.method = SuperpixelMethod::kQuickShift};
  cv::Mat one, two;
  {
    const ThreadLimit limit(1);
    one = ScanSuperpixels(scan, options);
  }
  {
    const ThreadLimit limit(2);
    two = ScanSuperpixels(scan, options);
  }
  EXPECT_EQ(cv::countNonZero(one != two), 0);
}

}  // namespace
}  // namespace lidarshop
