// Completion by shifted copies at the dominant patch offsets (offset_completion.h).
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/inpaint/offset_completion.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// A facade seen straight on: wall, and windows 23 columns apart with a sill below each (3 channels).
cv::Mat Facade(int rows, int cols) {
  cv::Mat image(rows, cols, CV_32FC3, cv::Scalar(200, 190, 170));
  for (int x0 = 4; x0 + 12 < cols; x0 += 23) {
    for (int y0 : {6, 40}) {
      cv::rectangle(image, cv::Rect(x0, y0, 12, 20), cv::Scalar(50, 60, 80), cv::FILLED);
      cv::rectangle(image, cv::Rect(x0 - 1, y0 + 20, 14, 2), cv::Scalar(250, 250, 250), cv::FILLED);
    }
  }
  return image;
}

// The lower half of a window and the wall below it are hidden; no patch along the hole's rim shows where the
// window ends, its neighbours do.
TEST(OffsetCompletion, RepeatedWindowsAreCompletedExactly) {
  const cv::Mat image = Facade(70, 140);
  cv::Mat hole = cv::Mat::zeros(image.size(), CV_8U);
  cv::rectangle(hole, cv::Rect(60, 14, 30, 24), cv::Scalar(255), cv::FILLED);
  const OffsetCompletionResult result = CompleteByOffsets(image, hole);
  ASSERT_FALSE(result.offsets.empty());
  // The window pitch (a multiple of 23 columns, no row shift) is among the dominant offsets.
  bool pitch = false;
  for (const cv::Point& o : result.offsets) pitch |= o.y == 0 && o.x != 0 && o.x % 23 == 0;
  EXPECT_TRUE(pitch);
  EXPECT_EQ(result.unfilled, 0);
  int wrong = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      if (!hole.at<uint8_t>(y, x)) {
        EXPECT_EQ(result.label.at<int32_t>(y, x), -1);
        continue;
      }
      const cv::Vec2i s = result.source_pixel.at<cv::Vec2i>(y, x);
      ASSERT_GE(s[0], 0);
      ASSERT_FALSE(hole.at<uint8_t>(s[0], s[1]));  // copies come from outside the hole
      wrong += image.at<cv::Vec3f>(s[0], s[1]) != image.at<cv::Vec3f>(y, x) ? 1 : 0;
    }
  EXPECT_EQ(wrong, 0);
  // The greedy patch fill, which sees only the rim, gets part of it wrong: the reason for the method.
  const InpaintResult greedy = Inpaint(image, hole, {});
  int greedy_wrong = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      greedy_wrong += hole.at<uint8_t>(y, x) && greedy.image.at<cv::Vec3f>(y, x) != image.at<cv::Vec3f>(y, x);
  EXPECT_GT(greedy_wrong, 20);
}

TEST(OffsetCompletion, SameLabelsOnAnyThreadCount) {
  cv::Mat image = Facade(70, 140);
  cv::RNG rng(5);
  cv::Mat noise(image.size(), CV_32FC3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 4.0);
  image += noise;
  cv::Mat hole = cv::Mat::zeros(image.size(), CV_8U);
  cv::circle(hole, {70, 30}, 14, cv::Scalar(255), cv::FILLED);
  OffsetCompletionResult one, two;
  {
    ThreadLimit limit(1);
    one = CompleteByOffsets(image, hole);
  }
  {
    ThreadLimit limit(2);
    two = CompleteByOffsets(image, hole);
  }
  EXPECT_EQ(one.offsets, two.offsets);
  EXPECT_EQ(cv::countNonZero(one.label != two.label), 0);
  EXPECT_EQ(one.energy, two.energy);
}

TEST(OffsetCompletion, BadInputAndOptions) {
  const cv::Mat image = Facade(40, 60);
  EXPECT_THROW(CompleteByOffsets(image, cv::Mat::zeros(30, 60, CV_8U)), InputError);
  EXPECT_THROW(CompleteByOffsets(cv::Mat(40, 60, CV_8UC3), cv::Mat::zeros(40, 60, CV_8U)), InputError);
  OffsetCompletionOptions options;
  options.labels = 0;
  EXPECT_THROW(CompleteByOffsets(image, cv::Mat::zeros(40, 60, CV_8U), options), OptionsError);
  options = {};
  options.channel_weights = {1.0f};
  EXPECT_THROW(CompleteByOffsets(image, cv::Mat::zeros(40, 60, CV_8U), options), OptionsError);
  // A hole covering everything: nothing to copy, every pixel stays unfilled, no crash.
  const OffsetCompletionResult all = CompleteByOffsets(image, cv::Mat(40, 60, CV_8U, cv::Scalar(255)));
  EXPECT_EQ(all.unfilled, 40 * 60);
  EXPECT_TRUE(all.offsets.empty());
}

}  // namespace
}  // namespace lidarshop
