// The coarse-to-fine sweep (sweep.h, sweep_bound.h) against the full grid: on the built-in parking lot and on
// a synthetic lot of two-box cars it gives the same detections, the same refined poses and, for every pose
// it verifies, the same values; every pose it skips has a true confidence below its bound and below the
// thresholds. And the heat-map pictures carry their axes, the scanner and the scene points.
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scanner/primitives.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/sweep_bound.h"
#include "lidarshop/verify/verify.h"
#include "lidarshop/verify/verify_test_util.h"

namespace lidarshop {
namespace {

using verify_testing::LabeledMesh;
using verify_testing::MakeBox;
using verify_testing::MakeCar;

// Sweep options over x in [x_min, x_max] and y in [y_min, y_max], metres; the rest default.
SweepOptions Area(double x_min_m, double x_max_m, double y_min_m, double y_max_m) {
  SweepOptions options;
  options.x_min_m = x_min_m;
  options.x_max_m = x_max_m;
  options.y_min_m = y_min_m;
  options.y_max_m = y_max_m;
  return options;
}

// Two two-box cars, a wall and the ground, scanned noise-free from (0, 0, 1.6) over 120° x 60° at 0.2°.
std::vector<PreparedScan> SyntheticLot() {
  std::vector<LabeledMesh> meshes;
  meshes.push_back({MakeBox(Eigen::Vector3f(-15, -2, -0.1f), Eigen::Vector3f(15, 20, 0), 4), 0});
  meshes.push_back({MakeBox(Eigen::Vector3f(-15, 16, 0), Eigen::Vector3f(15, 16.3f, 3), 4), 1});
  meshes.push_back({TransformMesh(MakeCar(), PoseFromXyzYaw(-3.1, 9.2, 0, 30)), 2});
  meshes.push_back({TransformMesh(MakeCar(), PoseFromXyzYaw(4.05, 10.4, 0, 100)), 3});
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  world_from_scanner(2, 3) = 1.6;
  return {PrepareScan(verify_testing::SyntheticScan(meshes, world_from_scanner, 300, 600, -60, 60, -40, 20))};
}

std::string Describe(const std::vector<Detection>& detections) {
  std::string text;
  for (const Detection& d : detections) {
    text += fmt::format(" ({:.3f}, {:.3f}, {:.2f}°: {:.6f} / {:.6f})", d.x_m, d.y_m, d.yaw_deg, d.consistency,
                        d.confidence);
  }
  return text;
}

// Runs both searches and checks that they agree.
void ExpectSameAsFullGrid(const VerifierModel& model, std::span<const PreparedScan> scans,
                          SweepOptions options, size_t expected_detections) {
  options.search = SweepSearch::kFull;
  const SweepResult full = Sweep(model, scans, options, VerifyOptions());
  options.search = SweepSearch::kCoarseToFine;
  const SweepResult fast = Sweep(model, scans, options, VerifyOptions());
  fmt::print(
      "full grid: {} poses, {} detections:{}\ncoarse-to-fine: {} of {} poses verified, {} bounds, {} "
      "detections:{}\n",
      full.evaluated_poses, full.detections.size(), Describe(full.detections), fast.evaluated_poses,
      fast.poses.size(), fast.bound_evaluations, fast.detections.size(), Describe(fast.detections));
  EXPECT_EQ(full.evaluated_poses, static_cast<int64_t>(full.poses.size()));
  EXPECT_EQ(full.detections.size(), expected_detections) << Describe(full.detections);

  // The same detections: same poses, same values (bit for bit: the same code verified the same poses).
  EXPECT_EQ(fast.detections.size(), full.detections.size());
  for (size_t k = 0; k < std::min(fast.detections.size(), full.detections.size()); ++k) {
    const Detection& a = fast.detections[k];
    const Detection& b = full.detections[k];
    EXPECT_EQ(a.x_m, b.x_m);
    EXPECT_EQ(a.y_m, b.y_m);
    EXPECT_EQ(a.yaw_deg, b.yaw_deg);
    EXPECT_EQ(a.consistency, b.consistency);
    EXPECT_EQ(a.confidence, b.confidence);
    EXPECT_EQ(a.comparable_pairs, b.comparable_pairs);
    EXPECT_EQ(a.icp_cost_m, b.icp_cost_m);
  }
  // The same refinement: same seeds, same climbs.
  ASSERT_EQ(fast.refined.size(), full.refined.size());
  for (size_t k = 0; k < fast.refined.size(); ++k) {
    EXPECT_EQ(fast.refined[k].x_m, full.refined[k].x_m);
    EXPECT_EQ(fast.refined[k].y_m, full.refined[k].y_m);
    EXPECT_EQ(fast.refined[k].yaw_deg, full.refined[k].yaw_deg);
    EXPECT_EQ(fast.refined[k].result.confidence, full.refined[k].result.confidence);
  }
  EXPECT_EQ(fast.refine_evaluations, full.refine_evaluations);

  // Pose by pose: verified ones equal, skipped ones provably unable to pass.
  const double threshold = std::min(options.min_confidence, options.refine_min_confidence);
  int64_t skipped = 0;
  double worst_gap = 1.0;  // smallest bound − true confidence over the skipped poses
  for (size_t p = 0; p < full.poses.size(); ++p) {
    const SweepPose& a = fast.poses[p];
    const SweepPose& b = full.poses[p];
    if (a.evaluated) {
      EXPECT_EQ(a.result.confidence, b.result.confidence);
      EXPECT_EQ(a.result.comparable_pairs, b.result.comparable_pairs);
      continue;
    }
    ++skipped;
    worst_gap = std::min(worst_gap, a.confidence_bound - b.result.confidence);
    EXPECT_LE(b.result.confidence, a.confidence_bound) << "pose " << p;
    EXPECT_LE(a.confidence_bound, threshold);
  }
  EXPECT_EQ(skipped + fast.evaluated_poses, static_cast<int64_t>(fast.poses.size()));
  fmt::print("skipped {} poses; smallest bound − true confidence: {:.4f}\n", skipped, worst_gap);
  // It has to be worth it: most poses skipped.
  EXPECT_LT(fast.evaluated_poses, static_cast<int64_t>(full.poses.size()) / 2);
}

TEST(SweepSearch, SyntheticLotSameDetectionsAsFullGrid) {
  const std::vector<PreparedScan> scans = SyntheticLot();
  const VerifierModel model = PrepareModel(MakeCar());
  SweepOptions options = Area(-7, 7, 5, 14);
  options.step_m = 0.25;
  options.yaws_deg = {0, 30, 60, 90, 120, 150};
  // One view of a two-box car shows about a fifth of it.
  options.min_confidence = 0.15;
  ExpectSameAsFullGrid(model, scans, options, 2);
}

TEST(SweepSearch, ParkingLotSameDetectionsAsFullGrid) {
  const SceneDescription scene = test_scenes::LoadBuiltinScene("parking_lot");
  const std::vector<PreparedScan> scans = {PrepareScan(test_scenes::ScanScene(scene))};
  CarMeshOptions mesh_options;
  mesh_options.style = ParseCarStyle("sedan", "test");
  const VerifierModel model = PrepareModel(MakeCarMesh(mesh_options));
  // The default grid's x range, its near half in y (the cars stand at y 10–11 m), every 0.5 m and 30°.
  SweepOptions options = Area(-10, 10, 2, 14);
  options.step_m = 0.5;
  options.yaws_deg = {0, 30, 60, 90, 120, 150};
  ExpectSameAsFullGrid(model, scans, options, 1);
}

// The bound directly: for random blocks, no pose within the block's radius has a larger confidence.
TEST(SweepSearch, BoundIsAboveEveryPoseOfTheBlock) {
  const std::vector<PreparedScan> scans = SyntheticLot();
  const VerifierModel model = PrepareModel(MakeCar());
  SweepOptions options = Area(-7, 7, 5, 14);
  const verify_internal::SweepConfidenceBound bound(model, scans, options, VerifyOptions().sigma_m, 2.0);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(-7, 7), y(5, 14), yaw(0, 360), unit(0, 1);
  int tight = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const double cx = x(random), cy = y(random), theta = yaw(random), radius = 2.0 * unit(random);
    const double upper = bound.UpperBound(cx, cy, theta, radius, 2.0);
    for (int k = 0; k < 6; ++k) {
      const double angle = 2 * std::numbers::pi * unit(random), distance = radius * std::sqrt(unit(random));
      const VerifyResult r = VerifyPose(
          model, scans,
          PoseFromXyzYaw(cx + distance * std::cos(angle), cy + distance * std::sin(angle), 0, theta));
      EXPECT_LE(r.confidence, upper) << fmt::format("block ({}, {}, {}°, r {})", cx, cy, theta, radius);
      tight += upper < 0.05;
    }
    // At the centre with radius 0, the bound is the share of the model with a scene point within reach: at
    // least the confidence, and not everything.
    const VerifyResult centre = VerifyPose(model, scans, PoseFromXyzYaw(cx, cy, 0, theta));
    EXPECT_LE(centre.confidence, bound.UpperBound(cx, cy, theta, 0.0, 2.0));
  }
  // Not vacuous: some blocks are bounded below the refinement threshold.
  EXPECT_GT(tight, 0);
}

TEST(SweepSearch, FullSearchVerifiesEveryPose) {
  const std::vector<PreparedScan> scans = SyntheticLot();
  const VerifierModel model = PrepareModel(MakeCar());
  SweepOptions options = Area(-1, 1, 2, 3);
  options.step_m = 0.5;
  options.yaws_deg = {0, 90};
  options.search = SweepSearch::kFull;
  const SweepResult sweep = Sweep(model, scans, options, VerifyOptions());
  EXPECT_EQ(sweep.evaluated_poses, 30);
  EXPECT_EQ(sweep.bound_evaluations, 0);
  for (const SweepPose& pose : sweep.poses) EXPECT_TRUE(pose.evaluated);
  EXPECT_EQ(cv::countNonZero(sweep.evaluated_map == 2), 15);
}

cv::Vec3b PixelAt(const cv::Mat& rgb, cv::Point2d p) {
  return rgb.at<cv::Vec3b>(static_cast<int>(std::floor(p.y)), static_cast<int>(std::floor(p.x)));
}

// The picture of a hand-made sweep: the scanner at (0, 0) is magenta at its pixel, the axes have tick marks
// and labels in metres, the frame is black, skipped cells are pale and scene points darken the cells.
TEST(SweepHeatMap, AxesScannerAndPoints) {
  SweepResult sweep;
  for (int i = 0; i < 9; ++i) sweep.xs_m.push_back(-2.0 + 0.5 * i);
  for (int i = 0; i < 9; ++i) sweep.ys_m.push_back(0.5 * i);
  sweep.confidence_map = cv::Mat(9, 9, CV_32F, cv::Scalar(0.5f));
  sweep.evaluated_map = cv::Mat(9, 9, CV_8U, cv::Scalar(1));
  sweep.evaluated_map(cv::Rect(0, 5, 4, 4)).setTo(0);  // x −2..−0.5, y 0..1.5: skipped
  sweep.confidence_map.setTo(std::numeric_limits<float>::quiet_NaN(), sweep.evaluated_map == 0);
  sweep.scanner_xy_m = {Eigen::Vector2d(0, 0)};
  sweep.scene_xy_m = {Eigen::Vector2f(-1.5f, 0.5f), Eigen::Vector2f(1.5f, 3.5f)};
  const int cell_px = 20;
  const cv::Mat picture = RenderHeatMap(sweep.confidence_map, sweep, "confidence", 0.3, cell_px);
  const HeatMapLayout layout = HeatMapLayoutOf(sweep.confidence_map, sweep, cell_px);
  ASSERT_EQ(picture.type(), CV_8UC3);
  EXPECT_EQ(layout.map.width, 9 * cell_px);
  EXPECT_EQ(layout.map.height, 9 * cell_px);
  EXPECT_EQ(PixelAt(picture, layout.PixelOf(0.0, 0.0)), kHeatMapScannerRgb);
  EXPECT_NE(PixelAt(picture, layout.PixelOf(1.0, 2.0)), kHeatMapScannerRgb);
  // Ticks every metre below the map: black at x = 0 m (a cell centre: ticks sit at metres), white between.
  const int below = layout.map.y + layout.map.height + 3;
  const int tick_x = static_cast<int>(std::lround(layout.PixelOf(0.0, 0.0).x - 0.5 * cell_px));
  EXPECT_EQ(picture.at<cv::Vec3b>(below, tick_x), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(picture.at<cv::Vec3b>(below, tick_x + cell_px / 2 + 3), cv::Vec3b(255, 255, 255));
  // Ticks left of the map, at y = 2 m.
  const int tick_y = static_cast<int>(std::lround(layout.PixelOf(0.0, 2.0).y - 0.5 * cell_px));
  EXPECT_EQ(picture.at<cv::Vec3b>(tick_y, layout.map.x - 3), cv::Vec3b(0, 0, 0));
  // Tick labels: dark text pixels left of and below the map.
  cv::Mat gray;
  cv::cvtColor(picture, gray, cv::COLOR_RGB2GRAY);
  EXPECT_GT(cv::countNonZero(gray(cv::Rect(0, layout.map.y, layout.map.x - 8, layout.map.height)) < 100), 20);
  EXPECT_GT(cv::countNonZero(gray(cv::Rect(layout.map.x, below + 4, layout.map.width, 14)) < 100), 20);
  // The frame.
  EXPECT_EQ(picture.at<cv::Vec3b>(layout.map.y - 1, layout.map.x + 7), cv::Vec3b(0, 0, 0));
  // A skipped cell is pale; a scene point in it darkens its pixel (236 · 0.6 ≈ 142); an evaluated cell with a
  // point under it is darker than without.
  EXPECT_EQ(PixelAt(picture, layout.PixelOf(-1.5, 0.25)), cv::Vec3b(236, 236, 236));
  EXPECT_EQ(PixelAt(picture, layout.PixelOf(-1.5, 0.5)), cv::Vec3b(142, 142, 142));
  const cv::Vec3b plain = PixelAt(picture, layout.PixelOf(1.5, 3.25));
  const cv::Vec3b shaded = PixelAt(picture, layout.PixelOf(1.5, 3.5));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(shaded[k], 0.6 * plain[k], 1.0);
  EXPECT_GT(plain[0] + plain[1] + plain[2], shaded[0] + shaded[1] + shaded[2]);
}

// A sweep records what the picture needs: the scanner's x, y and the scene points above the ground.
TEST(SweepHeatMap, SweepCollectsScannerAndScenePoints) {
  const std::vector<PreparedScan> scans = SyntheticLot();
  const VerifierModel model = PrepareModel(MakeCar());
  SweepOptions options = Area(-5, 5, 8, 12);
  options.step_m = 1;
  options.yaws_deg = {0};
  const SweepResult sweep = Sweep(model, scans, options, VerifyOptions());
  ASSERT_EQ(sweep.scanner_xy_m.size(), 1u);
  EXPECT_EQ(sweep.scanner_xy_m[0], Eigen::Vector2d(0, 0));
  // Points of both cars (their bodies, 0.45–1.5 m up) and none of the ground.
  int near_left = 0, near_right = 0;
  for (const Eigen::Vector2f& p : sweep.scene_xy_m) {
    near_left += std::hypot(p.x() + 3.1, p.y() - 9.2) < 2.6;
    near_right += std::hypot(p.x() - 4.05, p.y() - 10.4) < 2.6;
  }
  EXPECT_GT(near_left, 100);
  EXPECT_GT(near_right, 100);
  EXPECT_EQ(near_left + near_right, static_cast<int>(sweep.scene_xy_m.size()));
}

}  // namespace
}  // namespace lidarshop
