#include "lidarshop/recolor/resection.h"

#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/recolor/recolor_eval.h"
#include "lidarshop/recolor/resection_test_util.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_resection::MakePairs;
using testing_resection::TrueCamera;

ResectionOptions Options(const PinholeCamera& camera) {
  ResectionOptions options;
  options.width_px = camera.width_px;
  options.height_px = camera.height_px;
  return options;
}

// Draws of bench/results/recolor.md's 10-pair rows: 8 right pairs and 2 outliers (0.5 px noise) from the scan
// of MakeRecolorScene, seen by the evaluation camera `offset_m` from the scanner; `exact` the noise-free pairs.
struct TenPairDraw {
  PinholeCamera truth;
  std::vector<PixelPointPair> pairs, exact;
};
class RecolorSceneDraws {
 public:
  RecolorSceneDraws() : scene_(test_scenes::MakeRecolorScene()), scan_(test_scenes::ScanScene(scene_)) {}
  TenPairDraw Draw(double offset_m, uint64_t draw_seed) {
    TenPairDraw draw;
    draw.truth = EvaluationCamera(offset_m);
    auto [depth, fresh] = depth_m_.try_emplace(offset_m);  // one rendering per camera
    if (fresh) depth->second = RenderPhoto(scene_, draw.truth).depth_m;
    draw.pairs = DrawCorrespondences(scan_, draw.truth, depth->second, 10, 0.5, 0.2, draw_seed, &draw.exact);
    return draw;
  }

 private:
  SceneDescription scene_;
  Scan scan_;
  std::map<double, cv::Mat> depth_m_;
};

TEST(Resection, DltIsExactWithoutNoiseAndDecomposesIntoTheTrueCamera) {
  const PinholeCamera truth = TrueCamera();
  const std::vector<PixelPointPair> pairs = MakePairs(truth, 8, 0.0, 0.0, 3);
  const PinholeCamera camera = CameraFromProjection(NormalizedDlt(pairs), truth.width_px, truth.height_px);
  EXPECT_NEAR(camera.fx_px, truth.fx_px, 1e-5);
  EXPECT_NEAR(camera.fy_px, truth.fy_px, 1e-5);
  EXPECT_NEAR(camera.cx_px, truth.cx_px, 1e-5);
  EXPECT_NEAR(camera.cy_px, truth.cy_px, 1e-5);
  EXPECT_NEAR(camera.skew_px, 0, 1e-5);
  EXPECT_LT((camera.world_from_camera - truth.world_from_camera).norm(), 1e-7);
  EXPECT_LT(RmsReprojectionError(camera, pairs), 1e-6);
}

TEST(Resection, RansacAndRefinementMeetTheTargetWithNoiseAndOutliers) {
  const PinholeCamera truth = TrueCamera();
  for (int count : {10, 20, 40}) {
    double sum_rms = 0;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      std::vector<PixelPointPair> exact;
      const std::vector<PixelPointPair> pairs = MakePairs(truth, count, 0.5, 0.2, seed, &exact);
      const ResectionResult result = Resection(pairs, Options(truth));
      // The outliers (the first 20 %) are found, every other pair is kept.
      for (int i = 0; i < count; ++i) EXPECT_EQ(result.inlier[i], i >= std::round(0.2 * count) ? 1 : 0) << i;
      // Single draws of the noise can exceed 0.5 px (10 pairs = 8 inliers: 16 residuals for 7 unknowns, the
      // principal point held at the centre although this camera has it 3 px off); the mean over draws stays
      // under 0.5 px.
      const double rms_true = RmsReprojectionError(result.camera, exact);
      sum_rms += rms_true;
      EXPECT_LT(rms_true, 0.75) << count << " pairs, seed " << seed;
      EXPECT_LT(result.rms_px, 1.0);
      EXPECT_LT((result.camera.center_in_world() - truth.center_in_world()).norm(), 0.1);
    }
    EXPECT_LT(sum_rms / 8, 0.5) << count << " pairs";
  }
}

// bench/results/recolor.md's 10-pair rows: 8 inliers and 2 outliers, pairs drawn from the scan of
// MakeRecolorScene seen by a camera 1 and 3 m from the scanner. Before LO-RANSAC and the principal-point
// prior the 3 m draw with seed 3 kept an outlier (22 px) and the 1 m rows averaged 0.71 px.
TEST(Resection, TenPairsWithTwoOutliersStayUnderHalfAPixel) {
  RecolorSceneDraws draws;
  for (double offset : {1.0, 3.0}) {
    double sum_rms = 0;
    for (int seed = 1; seed <= 5; ++seed) {
      const TenPairDraw draw = draws.Draw(offset, 100 * seed + 10);
      ResectionOptions options = Options(draw.truth);
      options.seed = seed;
      const ResectionResult result = Resection(draw.pairs, options);
      for (int i = 0; i < 10; ++i)
        EXPECT_EQ(result.inlier[i], i >= 2 ? 1 : 0) << offset << " m, seed " << seed;
      const double rms = RmsReprojectionError(result.camera, draw.exact);
      EXPECT_LT(rms, 0.75) << offset << " m, seed " << seed;
      sum_rms += rms;
      // Eight inliers do not support a free principal point: it stays at the centre.
      EXPECT_EQ(result.camera.cx_px, 400.0);
      EXPECT_EQ(result.camera.cy_px, 300.0);
    }
    EXPECT_LT(sum_rms / 5, 0.5) << offset << " m";
  }
}

TEST(Resection, TheOldSettingsKeptAnOutlierOnTheWorstDraw) {
  // The 3 m draw with seed 3 of bench/results/recolor.md. Before this change (no local optimization, the
  // adaptive bound alone: 31 sets, the principal point free with 8 inliers) RANSAC kept the first set that
  // collected 8 pairs, one of them an outlier: 22 px on the true pairs.
  const TenPairDraw draw = RecolorSceneDraws().Draw(3.0, 310);
  const std::vector<PixelPointPair>& pairs = draw.pairs;
  const std::vector<PixelPointPair>& exact = draw.exact;
  ResectionOptions options = Options(draw.truth);
  options.seed = 3;
  const ResectionResult ours = Resection(pairs, options);
  EXPECT_LT(RmsReprojectionError(ours.camera, exact), 0.5);
  ResectionOptions old = options;
  old.local_optimization = false;
  old.ransac_min_iterations = 1;
  old.min_inliers_for_principal_point = 6;
  const ResectionResult before = Resection(pairs, old);
  EXPECT_EQ(before.inlier[1], 1);  // an outlier kept
  EXPECT_GT(RmsReprojectionError(before.camera, exact), 5.0);
  // Local optimization alone already rejects that set: the refitted 8-pair camera with the outlier explains
  // the pairs worse than the right one.
  ResectionOptions lo = old;
  lo.local_optimization = true;
  EXPECT_LT(RmsReprojectionError(Resection(pairs, lo).camera, exact), 0.5);
}

TEST(Resection, AnAbsorbedOutlierLosesToTheRightSet) {
  // Two draws of 10 pairs (8 right, 2 outliers) from the 30-draw runs of bench/results/recolor.md where the
  // camera bent to keep an outlier at the 4 px threshold. 1 m, seed 21: 9 pairs at 0.3-3.4 px (outlier
  // included) against 8 at 0.5 px; the right sets had fewer inliers and were never refitted: 6.4 px on the true
  // pairs. Now a set is also refitted when its MSAC score beats the best's. 3 m, seed 21: the outlier traded for
  // a right pair (5.6 px), 8 pairs as tight as the right 8: 6.7 px. Now the swap search trades it back.
  RecolorSceneDraws draws;
  for (double offset : {1.0, 3.0}) {
    const TenPairDraw draw = draws.Draw(offset, 2110);
    ResectionOptions options = Options(draw.truth);
    options.seed = 21;
    const ResectionResult result = Resection(draw.pairs, options);
    for (int i = 0; i < 10; ++i) EXPECT_EQ(result.inlier[i], i >= 2 ? 1 : 0) << offset << " m, pair " << i;
    EXPECT_LT(RmsReprojectionError(result.camera, draw.exact), 0.75) << offset << " m";
  }
}

TEST(Resection, NearPlanarDrawsGetTheCameraOfTheIntrinsicsPrior) {
  // The 1 m draw with seed 11: no minimal DLT of these 10 pairs is a plausible camera (the points nearly lie on
  // one plane), so RANSAC without local optimization finds no set; the prior's camera (square pixels, principal
  // point at the centre, f and pose from EPnP + LM) does.
  const TenPairDraw draw = RecolorSceneDraws().Draw(1.0, 1110);
  ResectionOptions options = Options(draw.truth);
  options.seed = 11;
  const ResectionResult result = Resection(draw.pairs, options);
  EXPECT_EQ(result.num_inliers, 8);
  EXPECT_LT(RmsReprojectionError(result.camera, draw.exact), 1.0);
  options.local_optimization = false;
  EXPECT_THROW(Resection(draw.pairs, options), InputError);
}

TEST(Resection, SameSeedSameCamera) {
  const PinholeCamera truth = TrueCamera();
  const std::vector<PixelPointPair> pairs = MakePairs(truth, 25, 0.5, 0.2, 9);
  const ResectionResult a = Resection(pairs, Options(truth));
  const ResectionResult b = Resection(pairs, Options(truth));
  EXPECT_EQ(a.camera.world_from_camera, b.camera.world_from_camera);
  EXPECT_EQ(a.camera.fx_px, b.camera.fx_px);
}

TEST(Resection, KnownIntrinsicsHandlePlanarTargets) {
  PinholeCamera truth = TrueCamera();
  std::vector<PixelPointPair> pairs = MakePairs(truth, 12, 0.0, 0.0, 4);
  for (PixelPointPair& pair : pairs) pair.point_in_world.y() = 6.0;  // a wall; project again
  for (PixelPointPair& pair : pairs)
    ASSERT_TRUE(ProjectWorldPoint(truth, pair.point_in_world, &pair.pixel_px));
  EXPECT_THROW(Resection(pairs, Options(truth)), InputError);
  const ResectionResult result = ResectWithIntrinsics(pairs, truth, Options(truth));
  EXPECT_LT(result.rms_px, 1e-3);
  EXPECT_LT((result.camera.world_from_camera - truth.world_from_camera).norm(), 1e-4);
}

TEST(Resection, RefusesDegenerateInputWithAReason) {
  const PinholeCamera truth = TrueCamera();
  const auto message = [&](std::vector<PixelPointPair> pairs) -> std::string {
    try {
      Resection(pairs, Options(truth), "c.json");
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  };
  EXPECT_NE(message(MakePairs(truth, 5, 0, 0, 1)).find("at least 6 pairs, got 5"), std::string::npos);
  std::vector<PixelPointPair> nan = MakePairs(truth, 10, 0, 0, 1);
  nan[3].point_in_world.z() = std::nan("");
  EXPECT_NE(message(nan).find("c.json: pairs[3]"), std::string::npos) << message(nan);
  std::vector<PixelPointPair> collinear = MakePairs(truth, 10, 0, 0, 1);
  for (PixelPointPair& pair : collinear) pair.pixel_px.y() = 2 * pair.pixel_px.x() - 100;
  EXPECT_NE(message(collinear).find("collinear"), std::string::npos);
  std::vector<PixelPointPair> planar = MakePairs(truth, 10, 0, 0, 1);
  for (PixelPointPair& pair : planar) pair.point_in_world.z() = 0.5;
  EXPECT_NE(message(planar).find("one plane"), std::string::npos);
  ResectionOptions no_size;
  EXPECT_THROW(Resection(MakePairs(truth, 10, 0, 0, 1), no_size), OptionsError);
}

}  // namespace
}  // namespace lidarshop
