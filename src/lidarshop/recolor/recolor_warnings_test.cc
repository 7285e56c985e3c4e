// #35: a resection or a recolouring that looks wrong says so in its result's warnings, and a right one does not.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/resection_test_util.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"

namespace lidarshop {
namespace {

using testing_resection::TrueCamera;

// `count` points 3-9 m in front of `camera`, their pixels moved by `noise_px` RMS, no outliers.
std::vector<PixelPointPair> NoisyPairs(const PinholeCamera& camera, int count, double noise_px,
                                       uint64_t seed) {
  return testing_resection::MakePairs(camera, count, noise_px, 0.0, seed);
}

TEST(RecolorWarnings, AResectionWhosePairsAreOffByPixelsIsReported) {
  const PinholeCamera truth = TrueCamera();
  ResectionOptions options;
  options.width_px = truth.width_px;
  options.height_px = truth.height_px;
  options.ransac_threshold_px = 40;  // every pair is an inlier: the RMS is the pairs' own error
  const ResectionResult good = Resection(NoisyPairs(truth, 20, 0.5, 1), options);
  EXPECT_LT(good.rms_px, 1.0);
  EXPECT_TRUE(good.warnings.empty());
  const ResectionResult bad = Resection(NoisyPairs(truth, 20, 10.0, 1), options);
  ASSERT_GT(bad.rms_px, kResectionRmsWarningPx);
  ASSERT_EQ(bad.warnings.size(), 1u);
  EXPECT_NE(bad.warnings[0].find("RMS of"), std::string::npos) << bad.warnings[0];
  // Known intrinsics: the same check.
  EXPECT_EQ(ResectWithIntrinsics(NoisyPairs(truth, 20, 10.0, 2), truth, options).warnings.size(), 1u);
  EXPECT_TRUE(ResectWithIntrinsics(NoisyPairs(truth, 20, 0.5, 2), truth, options).warnings.empty());
}

// The recolouring scene of the evaluation (bench/results/recolor.md): its photo agrees with the scan's own
// colours and, without colour, with its intensity; the photo in negative (dark painted light) does not.
TEST(RecolorWarnings, APhotoThatDisagreesWithTheScansOwnBrightnessIsReported) {
  const SceneDescription scene = test_scenes::MakeRecolorScene();
  const Scan scan = test_scenes::ScanScene(scene);
  const PinholeCamera camera = CameraLookingAt({1.5, 0.3, 1.6}, {0, 10, 1.0}, 800, 600, 75);
  const cv::Mat photo = RenderPhoto(scene, camera).image;
  const RecolorResult right = RecolorScan(scan, photo, camera);
  EXPECT_LT(right.disagreement, 0.2);
  EXPECT_TRUE(right.warnings.empty()) << right.warnings.front();
  const cv::Mat negative = cv::Scalar::all(255) - photo;
  const RecolorResult wrong = RecolorScan(scan, negative, camera);
  EXPECT_GT(wrong.disagreement, kRecolorDisagreementLimit);
  ASSERT_EQ(wrong.warnings.size(), 1u);
  EXPECT_NE(wrong.warnings[0].find("disagree with the scan's own colours"), std::string::npos)
      << wrong.warnings[0];
  // Without colour the intensity is the reference.
  Scan grey = Clone(scan);
  grey.color.release();
  ASSERT_TRUE(grey.has_intensity());
  const RecolorResult grey_right = RecolorScan(grey, photo, camera);
  SCOPED_TRACE(grey_right.Summary());
  EXPECT_TRUE(grey_right.warnings.empty()) << grey_right.warnings.front();
  // Nothing to compare with: no warning, and the fraction is NaN.
  Scan bare = Clone(scan);
  bare.color.release();
  bare.intensity.release();
  EXPECT_TRUE(std::isnan(RecolorScan(bare, negative, camera).disagreement));
}

}  // namespace
}  // namespace lidarshop
