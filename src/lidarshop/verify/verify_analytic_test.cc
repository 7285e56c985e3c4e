// Analytic checks of consistency and confidence (thesis eqs. 4.1–4.5) on a car-sized box seen from the front.
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/verify/verify.h"
#include "lidarshop/verify/verify_test_util.h"

namespace lidarshop {
namespace {

using verify_testing::LabeledMesh;
using verify_testing::MakeBox;
using verify_testing::SyntheticScan;

// A 4 x 1.8 x 1.5 m box (model frame: centred on x/y, bottom at z = 0) standing at (0, 10, 0) on a ground
// slab, scanned from (0, 0, 0.75): only its front face (y = 9.1) is visible.
struct BoxScene {
  TriangleMesh model = MakeBox(Eigen::Vector3f(-2.0f, -0.9f, 0.0f), Eigen::Vector3f(2.0f, 0.9f, 1.5f), 10);
  Eigen::Matrix4d world_from_object = PoseFromXyzYaw(0, 10, 0, 0);
  Eigen::Matrix4d world_from_scanner = PoseFromXyzYaw(0, 0, 0.75, 0);

  Scan MakeScanWithDensity(int density) const {
    std::vector<LabeledMesh> meshes = {
        {TransformMesh(model, world_from_object), 1},
        {MakeBox(Eigen::Vector3f(-30, -5, -0.2f), Eigen::Vector3f(30, 40, 0.0f)), 2},
    };
    // 0.1° steps at density 1: ≈ 1.7 cm spacing at 10 m.
    return SyntheticScan(meshes, world_from_scanner, 150 * density + 1, 300 * density + 1, -15, 15, -10, 5);
  }
};

// Fraction of the model points visible from the scanner (the truth the confidence should approach).
double VisibleFraction(const VerifierModel& model, const Eigen::Matrix4d& world_from_model,
                       const Eigen::Matrix4d& world_from_scanner) {
  const Eigen::Matrix4d model_from_scanner = world_from_model.inverse() * world_from_scanner;
  const Eigen::Vector3f origin = model_from_scanner.topRightCorner<3, 1>().cast<float>();
  const auto points = model.points_in_model.points();
  std::vector<Ray> rays(points.size());
  std::vector<RayHit> hits(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    rays[i].origin = origin;
    rays[i].direction = (points[i] - origin).normalized();
  }
  model.scene_in_model.Cast(rays, hits);
  int visible = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (hits[i].hit() && std::abs(hits[i].t_hit - (points[i] - origin).norm()) < 1e-3f) ++visible;
  }
  return static_cast<double>(visible) / points.size();
}

class VerifyAnalyticTest : public ::testing::Test {
 protected:
  BoxScene scene_;
  VerifierModel model_ = PrepareModel(scene_.model);
  VerifyOptions options_;  // a = 10 cm, σ = 5 cm
};

TEST_F(VerifyAnalyticTest, ModelWhereTheObjectIsIsConsistentAndSeenAsFarAsVisible) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  // σ = 2 cm (still > the 1.7 cm spacing, so seen faces saturate): the kernel spills about 1.5σ over the
  // edges of the seen face onto unseen ones, which the default 5 cm would turn into +0.05 of confidence here.
  VerifyOptions options = options_;
  options.sigma_m = 0.02;
  const VerifyResult result = VerifyPose(model_, scans, scene_.world_from_object, options);
  ASSERT_TRUE(result.has_comparable_pairs);
  EXPECT_GT(result.comparable_pairs, 10000);
  EXPECT_DOUBLE_EQ(result.consistency, 1.0);
  const double visible = VisibleFraction(model_, scene_.world_from_object, scene_.world_from_scanner);
  // Front face 6 m² of 31.8 m².
  EXPECT_NEAR(visible, 6.0 / 31.8, 0.01);
  EXPECT_NEAR(result.confidence, visible, 0.03);
  // Mean distance to the nearest of 20,000 model points (≈ 4 cm apart): sampling-limited, not zero.
  EXPECT_LT(result.icp_cost_m, 0.03);
  EXPECT_GT(result.inlier_fraction, 0.9);
}

TEST_F(VerifyAnalyticTest, ModelOneMetreTowardTheScannerIsInconsistent) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  const VerifyResult result = VerifyPose(model_, scans, PoseFromXyzYaw(0, 9, 0, 0), options_);
  ASSERT_TRUE(result.has_comparable_pairs);
  EXPECT_LT(result.consistency, 0.05);
}

TEST_F(VerifyAnalyticTest, ModelInTheShadowIsConsistentButUnseen) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  const VerifyResult result = VerifyPose(model_, scans, PoseFromXyzYaw(0, 13, 0, 0), options_);
  ASSERT_TRUE(result.has_comparable_pairs);
  EXPECT_GT(result.consistency, 0.99);
  EXPECT_LT(result.confidence, 0.01);
}

TEST_F(VerifyAnalyticTest, DoublingScanDensityLeavesMeasuresNearlyUnchanged) {
  const std::vector<PreparedScan> coarse = {PrepareScan(scene_.MakeScanWithDensity(1))};
  const std::vector<PreparedScan> fine = {PrepareScan(scene_.MakeScanWithDensity(2))};
  for (const Eigen::Matrix4d& pose : {scene_.world_from_object, PoseFromXyzYaw(0, 9, 0, 0),
                                      PoseFromXyzYaw(0, 13, 0, 0), PoseFromXyzYaw(0.7, 10.4, 0, 20)}) {
    const VerifyResult a = VerifyPose(model_, coarse, pose, options_);
    const VerifyResult b = VerifyPose(model_, fine, pose, options_);
    EXPECT_GT(b.comparable_pairs, 3 * a.comparable_pairs);
    EXPECT_NEAR(a.consistency, b.consistency, 0.02);
    EXPECT_NEAR(a.confidence, b.confidence, 0.02);
  }
}

TEST_F(VerifyAnalyticTest, NoComparablePairIsReportedNotScoredAsOne) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  // Behind the scanner, outside its 30° field of view.
  const VerifyResult result = VerifyPose(model_, scans, PoseFromXyzYaw(0, -10, 0, 0), options_);
  EXPECT_FALSE(result.has_comparable_pairs);
  EXPECT_EQ(result.comparable_pairs, 0);
  EXPECT_TRUE(std::isnan(result.consistency));
  EXPECT_EQ(result.confidence, 0.0);
  EXPECT_NE(result.BriefReport().find("no comparable pair"), std::string::npos);
}

TEST_F(VerifyAnalyticTest, AReturnWithANonFinitePointIsRejectedByCell) {
  Scan scan = scene_.MakeScanWithDensity(1);
  int row = -1, col = -1;
  for (int r = 0; r < scan.rows && row < 0; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (scan.valid.at<uint8_t>(r, c) != 0) {
        row = r, col = c;
        break;
      }
    }
  }
  ASSERT_GE(row, 0);
  scan.point.at<cv::Vec3f>(row, col)[1] = std::numeric_limits<float>::quiet_NaN();
  try {
    PrepareScan(scan);
    FAIL() << "PrepareScan accepted a NaN point";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(fmt::format("row {}, column {}", row, col)), std::string::npos)
        << error.what();
  }
}

TEST_F(VerifyAnalyticTest, FootprintVisitsFewCellsAndGivesTheSameAnswerAsAFullWindow) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  VerifyOptions wide = options_;
  wide.footprint_margin_cells = 400;  // the whole scan
  for (const Eigen::Matrix4d& pose : {scene_.world_from_object, PoseFromXyzYaw(1.5, 12, 0, 30)}) {
    const VerifyResult narrow_result = VerifyPose(model_, scans, pose, options_);
    const VerifyResult wide_result = VerifyPose(model_, scans, pose, wide);
    EXPECT_LT(narrow_result.per_scan[0].footprint_cells, wide_result.per_scan[0].footprint_cells);
    EXPECT_EQ(narrow_result.comparable_pairs, wide_result.comparable_pairs);
    EXPECT_EQ(narrow_result.consistent_pairs, wide_result.consistent_pairs);
    EXPECT_DOUBLE_EQ(narrow_result.confidence, wide_result.confidence);
    EXPECT_EQ(narrow_result.icp_inliers, wide_result.icp_inliers);
  }
}

TEST_F(VerifyAnalyticTest, KernelGridAndKdTreeGiveTheSameAnswer) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  VerifyOptions other_sigma;
  other_sigma.sigma_m = 0.02;
  const VerifierModel kd_only = PrepareModel(scene_.model, ModelOptions(), other_sigma);
  ASSERT_TRUE(model_.kernel_grid.built());
  for (const Eigen::Matrix4d& pose : {scene_.world_from_object, PoseFromXyzYaw(0.4, 10.2, 0, 15)}) {
    const VerifyResult grid_result = VerifyPose(model_, scans, pose, options_);
    const VerifyResult kd_result = VerifyPose(kd_only, scans, pose, options_);
    EXPECT_NEAR(grid_result.confidence, kd_result.confidence, 1e-9);
    EXPECT_GT(grid_result.confidence, 0.05);
    EXPECT_EQ(grid_result.icp_inliers, kd_result.icp_inliers);
    EXPECT_NEAR(grid_result.icp_cost_m, kd_result.icp_cost_m, 1e-9);
  }
}

TEST_F(VerifyAnalyticTest, DetailsColourEveryPair) {
  const std::vector<PreparedScan> scans = {PrepareScan(scene_.MakeScanWithDensity(1))};
  VerifyOptions options = options_;
  options.keep_details = true;
  const VerifyResult result = VerifyPose(model_, scans, PoseFromXyzYaw(0, 9.5, 0, 0), options);
  ASSERT_EQ(result.scene_status.size(), 1u);
  EXPECT_EQ(cv::countNonZero(result.scene_status[0] == kConsistent), result.consistent_pairs);
  EXPECT_EQ(cv::countNonZero(result.scene_status[0] == kInconsistent),
            result.comparable_pairs - result.consistent_pairs);
  const PointCloud cloud = SceneStatusCloud(scans, result);
  EXPECT_EQ(static_cast<int64_t>(cloud.size()), scans[0].scan.CountValid());
  const PointCloud model_cloud = ObservedModelCloud(model_, PoseFromXyzYaw(0, 9.5, 0, 0), result);
  EXPECT_EQ(model_cloud.size(), model_.num_points());
}

TEST(VerifyOptionsTest, RejectsNonsense) {
  VerifyOptions options;
  options.sigma_m = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = VerifyOptions();
  options.allowance_m = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  ModelOptions model_options;
  model_options.num_surface_samples = 0;
  EXPECT_THROW(model_options.Check(), OptionsError);
  EXPECT_THROW(PrepareModel(TriangleMesh()), InputError);
}

TEST(VerifyModelTest, ShapeDistinctivenessWeightsDetailsAboveFlatFaces) {
  ModelOptions options;
  options.information = InformationWeighting::kShapeDistinctiveness;
  const VerifierModel model =
      PrepareModel(MakeBox(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(2, 2, 2), 4), options);
  double total = 0.0, corner_max = 0.0, centre_min = 1.0;
  const auto points = model.points_in_model.points();
  for (size_t i = 0; i < model.num_points(); ++i) {
    total += model.information[i];
    const Eigen::Vector3f p = points[i];
    const Eigen::Vector3f distance_to_centre = (p - Eigen::Vector3f(1, 1, 1)).cwiseAbs();
    // Face centres (two coordinates near 1) vs corners (all near 0 or 2).
    int central = 0, outer = 0;
    for (int k = 0; k < 3; ++k) {
      if (distance_to_centre[k] < 0.3f) ++central;
      if (distance_to_centre[k] > 0.9f) ++outer;
    }
    if (central == 2) centre_min = std::min(centre_min, static_cast<double>(model.information[i]));
    if (outer == 3) corner_max = std::max(corner_max, static_cast<double>(model.information[i]));
  }
  EXPECT_NEAR(total, 1.0, 1e-4);
  EXPECT_GT(corner_max, 3 * centre_min);
}

}  // namespace
}  // namespace lidarshop
