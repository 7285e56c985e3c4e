// The greedy fill loop: bookkeeping, border holes, determinism, structure continuation, the pluggable parts.
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/inpaint/debug_images.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Two flat regions split by a straight diagonal edge (slope 1), plus a little texture: exact copies of every
// edge patch exist along the edge.
cv::Mat DiagonalEdgeImage(int rows, int cols) {
  cv::Mat image(rows, cols, CV_32FC3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const bool dark = c - r < 10;
      const float texture = static_cast<float>(((r * 7 + c * 3) % 5));
      image.at<cv::Vec3f>(r, c) = dark ? cv::Vec3f(30 + texture, 40, 50) : cv::Vec3f(220, 200 + texture, 180);
    }
  return image;
}

cv::Mat TexturedImage(int rows, int cols, uint64_t seed) {
  cv::Mat image(rows, cols, CV_32FC3);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(image, image, cv::Size(7, 7), 2.0);
  return image;
}

void ExpectCompleteAndUntouched(const cv::Mat& image, const cv::Mat& mask, const InpaintResult& result) {
  ASSERT_EQ(result.image.size(), image.size());
  ASSERT_EQ(result.image.type(), image.type());
  int filled = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      if (mask.at<uint8_t>(r, c)) {
        EXPECT_GE(result.fill_iteration.at<int>(r, c), 0) << r << "," << c;
        ++filled;
      } else {
        EXPECT_EQ(result.fill_iteration.at<int>(r, c), -1);
        for (int k = 0; k < image.channels(); ++k)
          ASSERT_EQ(result.image.ptr<float>(r)[c * image.channels() + k],
                    image.ptr<float>(r)[c * image.channels() + k]);
      }
    }
  EXPECT_EQ(filled, result.hole_pixels);
  int sum = 0;
  for (const FillStep& step : result.steps) sum += step.filled_pixels;
  EXPECT_EQ(sum, result.hole_pixels);
  EXPECT_EQ(static_cast<int>(result.steps.size()), result.iterations);
}

TEST(InpaintFill, NonFiniteKnownPixelsAreRefusedNotSpread) {
  cv::Mat image(30, 40, CV_32F, cv::Scalar(1.0f));
  cv::Mat hole = cv::Mat::zeros(30, 40, CV_8U);
  cv::rectangle(hole, cv::Rect(15, 10, 6, 6), 255, cv::FILLED);
  image.at<float>(12, 17) = std::numeric_limits<float>::quiet_NaN();  // inside the hole: replaced
  const InpaintResult filled = Inpaint(image, hole, InpaintOptions{});
  EXPECT_TRUE(cv::checkRange(filled.image));
  image.at<float>(3, 30) = std::numeric_limits<float>::infinity();  // a known pixel: could be a source
  EXPECT_THROW(Inpaint(image, hole, InpaintOptions{}), InputError);
}

TEST(InpaintFill, FillFrontOfASmallMask) {
  cv::Mat known = cv::Mat::ones(5, 5, CV_8U);
  known(cv::Rect(1, 1, 3, 3)).setTo(0);
  const cv::Mat front = ComputeFillFront(known);
  // The 3x3 hole's ring is on the front, its centre is not.
  EXPECT_EQ(cv::countNonZero(front), 8);
  EXPECT_EQ(front.at<uint8_t>(2, 2), 0);
  EXPECT_EQ(front.at<uint8_t>(1, 1), 1);
}

// The original work's caveat: after a fill, no pixel may stay on the front that is not on it.
// check_bookkeeping compares the incremental front and priorities with a full recomputation after every fill
// and throws otherwise.
TEST(InpaintFill, BookkeepingLeavesNoStrandedFrontPixels) {
  const cv::Mat image = TexturedImage(60, 70, 1);
  std::vector<cv::Mat> masks;
  cv::Mat blob = cv::Mat::zeros(60, 70, CV_8U);
  cv::circle(blob, {35, 30}, 12, cv::Scalar(255), cv::FILLED);
  masks.push_back(blob);
  cv::Mat border = cv::Mat::zeros(60, 70, CV_8U);  // touches the top-left corner and the right border
  cv::rectangle(border, cv::Rect(0, 0, 15, 12), cv::Scalar(255), cv::FILLED);
  cv::rectangle(border, cv::Rect(60, 20, 10, 25), cv::Scalar(255), cv::FILLED);
  masks.push_back(border);
  cv::Mat speckle = cv::Mat::zeros(60, 70, CV_8U);  // isolated pixels, thin lines, several components
  for (int i = 0; i < 40; ++i) speckle.at<uint8_t>((i * 37) % 60, (i * 53) % 70) = 255;
  cv::line(speckle, {5, 50}, {65, 45}, cv::Scalar(255), 1);
  masks.push_back(speckle);
  for (const auto kind :
       {InpaintPriorityKind::kCriminisi, InpaintPriorityKind::kOnionPeel, InpaintPriorityKind::kRandom}) {
    for (const cv::Mat& mask : masks) {
      InpaintOptions options;
      options.patch_radius = 3;
      options.priority = kind;
      options.check_bookkeeping = true;
      InpaintResult result;
      ASSERT_NO_THROW(result = Inpaint(image, mask, options)) << static_cast<int>(kind);
      ExpectCompleteAndUntouched(image, mask, result);
    }
  }
}

TEST(InpaintFill, CriminisiContinuesAStraightEdgeExactly) {
  const cv::Mat image = DiagonalEdgeImage(80, 100);
  cv::Mat mask = cv::Mat::zeros(80, 100, CV_8U);
  cv::circle(mask, {50, 40}, 12, cv::Scalar(255), cv::FILLED);  // the edge c - r = 10 runs through the hole
  InpaintOptions options;
  options.check_bookkeeping = true;
  const InpaintResult result = Inpaint(image, mask, options);
  ExpectCompleteAndUntouched(image, mask, result);
  // Pixels on the wrong side of the edge after the fill: none (the texture may shift, the edge may not).
  int wrong_side = 0;
  for (int r = 0; r < 80; ++r)
    for (int c = 0; c < 100; ++c) {
      if (!mask.at<uint8_t>(r, c)) continue;
      const bool dark = result.image.at<cv::Vec3f>(r, c)[0] < 128.0f;
      wrong_side += dark != (c - r < 10) ? 1 : 0;
    }
  EXPECT_EQ(wrong_side, 0);
}

// A hole touching the border is filled from patches at the same distance from that border: the image's top
// two rows are a band of their own (a scan's sky above the last ground row), and a source patch that had to lie
// wholly inside the image could only bring rows from at least a patch radius further down.
TEST(InpaintFill, BorderRowsAreFilledFromBorderRows) {
  const int rows = 60, cols = 90;
  cv::Mat image(rows, cols, CV_32FC1);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) image.at<float>(r, c) = r < 2 ? 0.0f : 100.0f + 20.0f * ((r + c) % 3);
  cv::Mat mask = cv::Mat::zeros(rows, cols, CV_8U);
  cv::rectangle(mask, cv::Rect(30, 0, 30, 20), cv::Scalar(255), cv::FILLED);  // touches the top border
  for (const auto search : {InpaintSearchKind::kExhaustive, InpaintSearchKind::kLocal,
                            InpaintSearchKind::kTwoStep, InpaintSearchKind::kPatchMatch}) {
    InpaintOptions options;
    options.patch_radius = 4;
    options.search = search;
    options.check_bookkeeping = true;
    const InpaintResult result = Inpaint(image, mask, options);
    ExpectCompleteAndUntouched(image, mask, result);
    int wrong = 0;
    for (int r = 0; r < 20; ++r)
      for (int c = 30; c < 60; ++c) wrong += (result.image.at<float>(r, c) == 0.0f) != (r < 2) ? 1 : 0;
    EXPECT_EQ(wrong, 0) << "search " << static_cast<int>(search);
    // Every copied pixel came from the same row (the band structure is periodic only along the rows).
    for (int c = 30; c < 60; ++c) EXPECT_EQ(result.source_pixel.at<cv::Vec2i>(0, c)[0], 0);
  }
}

TEST(InpaintFill, OnionPeelFillsFromTheRimInwards) {
  const cv::Mat image = TexturedImage(60, 60, 2);
  cv::Mat mask = cv::Mat::zeros(60, 60, CV_8U);
  cv::rectangle(mask, cv::Rect(20, 20, 20, 20), cv::Scalar(255), cv::FILLED);
  InpaintOptions options;
  options.priority = InpaintPriorityKind::kOnionPeel;
  options.patch_radius = 2;
  const InpaintResult result = Inpaint(image, mask, options);
  // The rim of the square is filled before its centre.
  EXPECT_LT(result.fill_iteration.at<int>(20, 30), result.fill_iteration.at<int>(30, 30));
  EXPECT_LT(result.fill_iteration.at<int>(39, 25), result.fill_iteration.at<int>(30, 30));
}

TEST(InpaintFill, SameResultForAnyThreadCountAndSeed) {
  const cv::Mat image = TexturedImage(70, 90, 4);
  cv::Mat mask = cv::Mat::zeros(70, 90, CV_8U);
  cv::ellipse(mask, {45, 35}, {15, 9}, 30, 0, 360, cv::Scalar(255), cv::FILLED);
  for (const auto search : {InpaintSearchKind::kExhaustive, InpaintSearchKind::kPatchMatch}) {
    InpaintOptions options;
    options.search = search;
    options.seed = 17;
    InpaintResult one, two;
    {
      ThreadLimit limit(1);
      one = Inpaint(image, mask, options);
    }
    {
      ThreadLimit limit(2);
      two = Inpaint(image, mask, options);
    }
    EXPECT_EQ(cv::norm(one.image, two.image, cv::NORM_INF), 0.0);
    ASSERT_EQ(one.steps.size(), two.steps.size());
    for (size_t i = 0; i < one.steps.size(); ++i) {
      EXPECT_EQ(one.steps[i].target, two.steps[i].target);
      EXPECT_EQ(one.steps[i].source, two.steps[i].source);
    }
  }
}

TEST(InpaintFill, ChosenSourcesAreValidAndCopied) {
  const cv::Mat image = TexturedImage(50, 60, 5);
  cv::Mat mask = cv::Mat::zeros(50, 60, CV_8U);
  cv::rectangle(mask, cv::Rect(45, 0, 15, 10), cv::Scalar(255), cv::FILLED);  // top-right corner
  InpaintOptions options;
  options.patch_radius = 4;
  const InpaintResult result = Inpaint(image, mask, options);
  ExpectCompleteAndUntouched(image, mask, result);
  const int R = options.patch_radius;
  for (const FillStep& step : result.steps) {
    // The source patch is inside the image and outside the hole.
    ASSERT_GE(step.source.row - R, 0);
    ASSERT_LT(step.source.row + R, 50);
    ASSERT_GE(step.source.col - R, 0);
    ASSERT_LT(step.source.col + R, 60);
    const cv::Rect box(step.source.col - R, step.source.row - R, 2 * R + 1, 2 * R + 1);
    EXPECT_EQ(cv::countNonZero(mask(box)), 0);
  }
  // Every filled pixel holds exactly the original pixel it says it came from.
  for (int r = 0; r < 50; ++r)
    for (int c = 0; c < 60; ++c) {
      const cv::Vec2i s = result.source_pixel.at<cv::Vec2i>(r, c);
      if (s[0] < 0) continue;
      EXPECT_EQ(result.image.at<cv::Vec3f>(r, c), image.at<cv::Vec3f>(s[0], s[1]));
    }
}

class RejectRightHalf : public PatchAcceptance {
 public:
  bool Accept(const InpaintCanvas& canvas, Pixel, const SourceCandidate& candidate) const override {
    return candidate.source.col < canvas.cols() / 2;
  }
};

// A textured image whose right half repeats its left one, and a hole in the left half: the hole's exact
// original, the best candidate everywhere, lies in the right half.
struct TwoHalves {
  cv::Mat image;
  cv::Mat mask = cv::Mat::zeros(60, 80, CV_8U);
  TwoHalves() {
    const cv::Mat half = TexturedImage(60, 40, 6);
    cv::hconcat(half, half, image);
    cv::circle(mask, {20, 30}, 6, cv::Scalar(255), cv::FILLED);
  }
};

TEST(InpaintFill, AcceptanceHookRejectsCandidates) {
  const auto [image, mask] = TwoHalves();
  InpaintOptions options;
  options.patch_radius = 3;
  options.acceptance_candidates = 400;
  InpaintStrategies strategies;
  strategies.acceptance = std::make_unique<RejectRightHalf>();
  const InpaintResult result = Inpaint(image, mask, options, std::move(strategies));
  EXPECT_EQ(result.acceptance_fallbacks, 0);
  int rejected = 0;
  for (const FillStep& step : result.steps) {
    EXPECT_LT(step.source.col, 40);
    rejected += step.rejected;
  }
  EXPECT_GT(rejected, 0);
}

// Every candidate fails; those from the right half outright (AcceptanceVerdict::hard). The fallback copies the
// best candidate that was not rejected outright, looking past the offered candidates when all of them were.
class RejectAllRightHalfOutright : public PatchAcceptance {
 public:
  bool Accept(const InpaintCanvas& canvas, Pixel target, const SourceCandidate& candidate) const override {
    return Judge(canvas, target, candidate).accepted;
  }
  AcceptanceVerdict Judge(const InpaintCanvas& canvas, Pixel,
                          const SourceCandidate& candidate) const override {
    AcceptanceVerdict verdict;
    verdict.accepted = false;
    verdict.margin = -1.0;
    verdict.hard = candidate.source.col >= canvas.cols() / 2;
    return verdict;
  }
};

TEST(InpaintFill, FallbacksSkipCandidatesRejectedOutright) {
  const auto [image, mask] = TwoHalves();
  InpaintOptions options;
  options.patch_radius = 3;
  options.search = InpaintSearchKind::kExhaustive;
  InpaintStrategies strategies;
  strategies.acceptance = std::make_unique<RejectAllRightHalfOutright>();
  const InpaintResult result = Inpaint(image, mask, options, std::move(strategies));
  EXPECT_EQ(result.acceptance_fallbacks, result.iterations);
  for (const FillStep& step : result.steps) EXPECT_LT(step.source.col, 40);
  // Without acceptance the best candidates come from the right half.
  const InpaintResult plain = Inpaint(image, mask, options);
  int right = 0;
  for (const FillStep& step : plain.steps) right += step.source.col >= 40;
  EXPECT_GT(right, 0);
}

TEST(InpaintFill, SingleChannelAndWeightedChannels) {
  cv::Mat image = TexturedImage(40, 50, 7), gray;
  cv::cvtColor(image, gray, cv::COLOR_RGB2GRAY);
  cv::Mat mask = cv::Mat::zeros(40, 50, CV_8U);
  cv::circle(mask, {25, 20}, 5, cv::Scalar(255), cv::FILLED);
  InpaintOptions options;
  options.patch_radius = 2;
  ExpectCompleteAndUntouched(gray, mask, Inpaint(gray, mask, options));
  options.channel_weights = {1.0f, 0.0f, 4.0f};
  ExpectCompleteAndUntouched(image, mask, Inpaint(image, mask, options));
}

TEST(InpaintFill, BadInputsAndOptionsAreRejected) {
  const cv::Mat image = TexturedImage(30, 30, 8);
  cv::Mat mask = cv::Mat::zeros(30, 30, CV_8U);
  mask.at<uint8_t>(15, 15) = 255;
  InpaintOptions options;
  options.patch_radius = 0;
  EXPECT_THROW(Inpaint(image, mask, options), OptionsError);
  options = {};
  options.channel_weights = {1.0f, 1.0f};
  EXPECT_THROW(Inpaint(image, mask, options), OptionsError);
  options = {};
  EXPECT_THROW(Inpaint(image, cv::Mat::zeros(20, 30, CV_8U), options), InputError);
  cv::Mat bytes;
  image.convertTo(bytes, CV_8U);
  EXPECT_THROW(Inpaint(bytes, mask, options), InputError);
  cv::Mat nan_image = image.clone();
  nan_image.at<cv::Vec3f>(2, 2)[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(Inpaint(nan_image, mask, options), InputError);
  nan_image.at<cv::Vec3f>(15, 15)[1] = std::numeric_limits<float>::quiet_NaN();  // in the hole: fine
  nan_image.at<cv::Vec3f>(2, 2)[1] = 1.0f;
  EXPECT_NO_THROW(Inpaint(nan_image, mask, options));
  // A hole that leaves no whole 11x11 patch.
  cv::Mat full = cv::Mat::zeros(30, 30, CV_8U);
  cv::rectangle(full, cv::Rect(5, 5, 20, 20), cv::Scalar(255), cv::FILLED);
  EXPECT_THROW(Inpaint(image, full, options), InputError);
  // No hole: the image comes back unchanged.
  const InpaintResult none = Inpaint(image, cv::Mat::zeros(30, 30, CV_8U), options);
  EXPECT_EQ(none.iterations, 0);
  EXPECT_EQ(cv::norm(none.image, image, cv::NORM_INF), 0.0);
}

TEST(InpaintFill, KnownGradientUsesOneSidedDifferencesAtTheHole) {
  cv::Mat image(5, 5, CV_32F);
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) image.at<float>(r, c) = static_cast<float>(10 * c + r * r);
  cv::Mat mask = cv::Mat::zeros(5, 5, CV_8U);
  mask.at<uint8_t>(2, 3) = 255;  // right neighbour of (2, 2)
  const InpaintCanvas canvas(image, mask, 1);
  const cv::Vec2d g = KnownGradient(canvas, {2, 2}, {});
  EXPECT_DOUBLE_EQ(g[1], 10.0);               // backward difference: (2,2) − (2,1)
  EXPECT_DOUBLE_EQ(g[0], 0.5 * (9.0 - 1.0));  // central along rows
  const cv::Vec2d corner = KnownGradient(canvas, {0, 0}, {});
  EXPECT_DOUBLE_EQ(corner[1], 10.0);  // forward at the image border
  EXPECT_DOUBLE_EQ(corner[0], 1.0);
  EXPECT_EQ(KnownGradient(canvas, {2, 3}, {}), cv::Vec2d(0, 0));
}

TEST(InpaintFill, DebugPicturesHaveTheImageSize) {
  const cv::Mat image = TexturedImage(40, 50, 9);
  cv::Mat mask = cv::Mat::zeros(40, 50, CV_8U);
  cv::circle(mask, {25, 20}, 6, cv::Scalar(255), cv::FILLED);
  InpaintOptions options;
  options.patch_radius = 3;
  const InpaintResult result = Inpaint(image, mask, options);
  for (const cv::Mat& picture : {RenderFillOrder(result, image), RenderSourceMap(result, image),
                                 RenderSourceLocations(result, options.patch_radius)}) {
    EXPECT_EQ(picture.size(), image.size());
    EXPECT_EQ(picture.type(), CV_8UC3);
  }
  // The first filled pixel is blue, the last red in the fill-order picture.
  const FillStep& first = result.steps.front();
  const cv::Vec3b first_colour =
      RenderFillOrder(result, image).at<cv::Vec3b>(first.target.row, first.target.col);
  EXPECT_GT(first_colour[2], first_colour[0]);
}

}  // namespace
}  // namespace lidarshop
