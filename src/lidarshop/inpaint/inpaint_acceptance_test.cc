// Acceptance tests on constructed patches whose right answer is known.
#include "lidarshop/inpaint/acceptance.h"

#include <gtest/gtest.h>

#include "lidarshop/inpaint/patch_difference.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

constexpr int kR = 3;  // 7 x 7 patches

// A grey image 0..255 (so the value range is 255) whose hole is the bottom half of the target patch at
// (10, 10): rows 10..13, cols 7..13. Pixel (0, 0) is 0 and (0, 1) is 255 to fix the range.
struct Scene {
  cv::Mat image = cv::Mat(30, 60, CV_32FC1, cv::Scalar(128));
  cv::Mat hole = cv::Mat::zeros(30, 60, CV_8U);
  Pixel target{10, 10};
  Scene() {
    image.at<float>(0, 0) = 0.0f;
    image.at<float>(0, 1) = 255.0f;
    hole(cv::Rect(7, 10, 7, 4)).setTo(255);
  }
  // Sets the target's known part (rows 7..9) and the source patch at `source` by a function of (dr, dc).
  template <typename F>
  void PaintTargetKnown(F value) {
    for (int dr = -kR; dr < 0; ++dr)
      for (int dc = -kR; dc <= kR; ++dc) image.at<float>(target.row + dr, target.col + dc) = value(dr, dc);
  }
  template <typename F>
  void PaintSource(Pixel source, F value) {
    for (int dr = -kR; dr <= kR; ++dr)
      for (int dc = -kR; dc <= kR; ++dc) image.at<float>(source.row + dr, source.col + dc) = value(dr, dc);
  }
  AcceptanceVerdict Judge(const AcceptanceOptions& options, Pixel source) const {
    InpaintCanvas canvas(image, hole, kR);
    auto acceptance = MakeAcceptance(options);
    acceptance->Initialize(canvas);
    return acceptance->Judge(canvas, target, {source, 0.0f});
  }
};

AcceptanceOptions Only(void (*enable)(AcceptanceOptions&)) {
  AcceptanceOptions options;
  options.enabled = true;
  enable(options);
  return options;
}

TEST(Acceptance, RegionsSplitKnownAndCopiedPixelsAndBands) {
  Scene scene;
  InpaintCanvas canvas(scene.image, scene.hole, kR);
  const AcceptanceRegions all = GatherRegions(canvas, scene.target, {10, 30}, 0, {0.0f}, {255.0f});
  EXPECT_EQ(all.patch_pixels, 49);
  EXPECT_EQ(all.hole_pixels, 28);
  EXPECT_EQ(all.known_count(), 21);
  EXPECT_EQ(all.copied_count(), 28);
  EXPECT_FLOAT_EQ(all.target_known[0], 128.0f / 255.0f);
  const AcceptanceRegions band = GatherRegions(canvas, scene.target, {10, 30}, 1, {0.0f}, {255.0f});
  EXPECT_EQ(band.known_count(), 7);   // row 9 only
  EXPECT_EQ(band.copied_count(), 7);  // row 10 only
}

// Fig. 7.1/7.3: the source's known part matches the target exactly (SSD 0), but what it would copy is dark.
TEST(Acceptance, MeanComparesTheCopiedRegionNotOnlyTheKnownOne) {
  Scene scene;
  const Pixel good{10, 30}, bad{10, 45};
  scene.PaintSource(bad, [](int dr, int) { return dr < 0 ? 128.0f : 20.0f; });
  const AcceptanceOptions mean = Only([](AcceptanceOptions& o) { o.mean.enabled = true; });
  EXPECT_TRUE(scene.Judge(mean, good).accepted);
  const AcceptanceVerdict verdict = scene.Judge(mean, bad);
  EXPECT_FALSE(verdict.accepted);
  EXPECT_EQ(verdict.test, "mean");
  EXPECT_NEAR(verdict.value, 108.0 / 255.0, 1e-5);
  EXPECT_LT(verdict.margin, 0.0);
  EXPECT_NE(verdict.Explain().find("rejected by mean"), std::string::npos);
  // Known-to-known alone (fig. 7.3a) cannot see it: the same test on K vs the source's K passes.
  AcceptanceOptions known_only = mean;
  known_only.also_known_to_known = true;
  known_only.min_region_pixels = 1000;  // too few copied pixels to judge: only K vs K is compared
  EXPECT_TRUE(scene.Judge(known_only, bad).accepted);
  const AcceptanceOptions representative =
      Only([](AcceptanceOptions& o) { o.representative.enabled = true; });
  EXPECT_FALSE(scene.Judge(representative, bad).accepted);
  EXPECT_TRUE(scene.Judge(representative, good).accepted);
}

// Same mean, different distribution: a black/white checker against flat grey.
TEST(Acceptance, HistogramsSeeWhatTheMeanDoesNot) {
  Scene scene;
  scene.PaintTargetKnown([](int dr, int dc) { return (dr + dc) % 2 ? 0.0f : 255.0f; });
  const Pixel flat{10, 30}, checker{10, 45};
  scene.PaintSource(checker, [](int dr, int dc) { return (dr + dc + 100) % 2 ? 0.0f : 255.0f; });
  EXPECT_TRUE(scene.Judge(Only([](AcceptanceOptions& o) { o.mean.enabled = true; }), flat).accepted);
  for (HistogramMetric metric : {HistogramMetric::kIntersection, HistogramMetric::kEarthMovers}) {
    AcceptanceOptions options = Only([](AcceptanceOptions& o) { o.histogram.enabled = true; });
    options.histogram.metric = metric;
    const AcceptanceVerdict verdict = scene.Judge(options, flat);
    EXPECT_FALSE(verdict.accepted) << static_cast<int>(metric);
    EXPECT_EQ(verdict.test, "histogram");
    EXPECT_TRUE(scene.Judge(options, checker).accepted) << scene.Judge(options, checker).Explain();
  }
}

// Values 97..103 against 104..110 (range 255): in 16 bins over the full range they share one bin; over
// the regions' own range (compressed) they do not overlap.
TEST(Acceptance, CompressedRangeHistogramResolvesSmallShifts) {
  Scene scene;
  scene.PaintTargetKnown([](int dr, int dc) { return 97.0f + (dc + kR); });
  const Pixel shifted{10, 30};
  scene.PaintSource(shifted, [](int, int dc) { return 104.0f + (dc + kR); });
  AcceptanceOptions options = Only([](AcceptanceOptions& o) { o.histogram.enabled = true; });
  options.histogram.max_distance = 0.2;
  options.histogram.metric = HistogramMetric::kIntersection;
  EXPECT_TRUE(scene.Judge(options, shifted).accepted) << scene.Judge(options, shifted).Explain();
  options.histogram.range = HistogramRange::kCompressed;
  EXPECT_FALSE(scene.Judge(options, shifted).accepted);
}

// The target's known half is white left / black right; the source would copy black left / white right.
// The whole regions have the same histogram; the left and right halves do not.
TEST(Acceptance, QuadrantHistogramsSeeSwappedSides) {
  Scene scene;
  scene.PaintTargetKnown([](int, int dc) { return dc <= 0 ? 255.0f : 0.0f; });
  const Pixel swapped{10, 30};
  scene.PaintSource(swapped, [](int dr, int dc) {
    if (dr < 0) return dc <= 0 ? 255.0f : 0.0f;
    return dc <= 0 ? 0.0f : 255.0f;
  });
  AcceptanceOptions options = Only([](AcceptanceOptions& o) { o.histogram.enabled = true; });
  // Whole regions: 4 of 7 columns white in K; 3 of 7 in H: nearly equal.
  EXPECT_TRUE(scene.Judge(options, swapped).accepted) << scene.Judge(options, swapped).Explain();
  options.histogram.quadrants = true;
  const AcceptanceVerdict verdict = scene.Judge(options, swapped);
  EXPECT_FALSE(verdict.accepted);
  EXPECT_EQ(verdict.test, "histogram-quadrants");
}

// Thesis fig. 7.9: against a textured target (σ per pixel), a flat patch at the texture's mean has an
// expected SSD of σ² per pixel and a patch of the same texture 2σ²: SSD ranks the flat patch first. The
// smooth-versus-textured test rejects it and accepts the textured one.
TEST(Acceptance, SmoothVersusTexturedSigmaSquaredCase) {
  Scene scene;
  cv::RNG rng(7);
  auto noise = [&](int, int) { return static_cast<float>(128.0 + rng.gaussian(30.0)); };
  scene.PaintTargetKnown(noise);
  const Pixel flat{10, 30}, textured{10, 45};
  scene.PaintSource(textured, noise);  // the same texture, another draw
  InpaintCanvas canvas(scene.image, scene.hole, kR);
  const auto ssd = WeightedSsd().ForTarget(canvas, scene.target);
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_LT(ssd->Evaluate(flat, inf), ssd->Evaluate(textured, inf));  // SSD prefers the flat patch
  const AcceptanceOptions options = Only([](AcceptanceOptions& o) { o.smooth_texture.enabled = true; });
  const AcceptanceVerdict verdict = scene.Judge(options, flat);
  EXPECT_FALSE(verdict.accepted);
  EXPECT_EQ(verdict.test, "smooth-texture");
  EXPECT_NEAR(verdict.value, 1.0, 1e-6);
  EXPECT_TRUE(scene.Judge(options, textured).accepted) << scene.Judge(options, textured).Explain();
  // Mean alone cannot tell them apart.
  EXPECT_TRUE(scene.Judge(Only([](AcceptanceOptions& o) { o.mean.enabled = true; }), flat).accepted);
}

TEST(Acceptance, SmallHolesAreAcceptedAutomatically) {
  Scene scene;
  scene.hole.setTo(0);
  scene.hole(cv::Rect(7, 13, 4, 1)).setTo(255);  // 4 of 49 pixels: 8 %
  const Pixel dark{10, 30};
  scene.PaintSource(dark, [](int, int) { return 0.0f; });
  AcceptanceOptions options = AcceptanceOptions::Combined();
  options.band_px = 0;
  options.min_region_pixels = 1;
  AcceptanceVerdict verdict = scene.Judge(options, dark);
  EXPECT_TRUE(verdict.accepted);
  EXPECT_EQ(verdict.test, "small hole");
  options.auto_accept_hole_fraction = 0.05;
  verdict = scene.Judge(options, dark);
  EXPECT_FALSE(verdict.accepted);
}

TEST(Acceptance, CombinedIsTheAndOfItsTestsAndUsesChannelWeights) {
  // Five channels; channel 3 of the copied region is far off, the others agree.
  cv::Mat image(30, 60, CV_32FC(5));
  image.reshape(1).setTo(0.5);
  cv::Mat hole = cv::Mat::zeros(30, 60, CV_8U);
  hole(cv::Rect(7, 10, 7, 4)).setTo(255);
  image.ptr<float>(0)[0 * 5 + 3] = 0.0f;
  image.ptr<float>(0)[1 * 5 + 3] = 1.0f;
  for (int k = 0; k < 5; ++k) image.ptr<float>(0)[k] = 0.0f, image.ptr<float>(0)[5 + k] = 1.0f;
  const Pixel source{10, 30};
  for (int dr = 0; dr <= kR; ++dr)
    for (int dc = -kR; dc <= kR; ++dc) image.ptr<float>(source.row + dr)[(source.col + dc) * 5 + 3] = 0.9f;
  InpaintCanvas canvas(image, hole, kR);
  AcceptanceOptions options = AcceptanceOptions::Combined();
  auto all = MakeAcceptance(options);
  all->Initialize(canvas);
  EXPECT_EQ(all->test_count(), 3u);
  EXPECT_FALSE(all->Judge(canvas, {10, 10}, {source, 0.0f}).accepted);
  auto blind = MakeAcceptance(options, {1, 1, 1, 0, 1});
  blind->Initialize(canvas);
  EXPECT_TRUE(blind->Judge(canvas, {10, 10}, {source, 0.0f}).accepted);
  options.enabled = false;
  EXPECT_EQ(MakeAcceptance(options), nullptr);
}

TEST(Acceptance, BadOptionsNameTheField) {
  AcceptanceOptions options;
  options.histogram.bins = 1;
  try {
    options.Check();
    FAIL();
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("histogram.bins"), std::string::npos);
  }
  options = {};
  options.band_px = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  options = {};
  options.mean.max_difference = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace lidarshop
