// The built-in parking lot (data/scenes/parking_lot.json: a sedan, a hatchback and a van, 4 mm range noise,
// one scanner): sweeps, the smaller-model weakness, and a pose halfway between two cars that consistency
// rejects while its trimmed ICP cost stays inside the trim.
#include <cmath>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "lidarshop/scanner/primitives.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {
namespace {

struct Car {
  std::string style;
  double x, y, yaw_deg;
};
// As placed in parking_lot.json (rotate_deg z = yaw).
const std::vector<Car> kCars = {{"sedan", -6.5, 10, 90}, {"hatchback", 0, 11, -90}, {"van", 6.5, 10.5, 78}};

class ParkingLotTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const SceneDescription scene = testing::LoadBuiltinScene("parking_lot");
    // The built-in 960 x 560 scan (0.125° steps: ≈ 2.2 cm at 10 m).
    scans_ = new std::vector<PreparedScan>{PrepareScan(testing::ScanScene(scene))};
  }
  static void TearDownTestSuite() { delete scans_; }
  static std::vector<PreparedScan>* scans_;
};
std::vector<PreparedScan>* ParkingLotTest::scans_ = nullptr;

SweepOptions CarSweep() {
  SweepOptions options;
  options.x_min_m = -9.3;  // positions 0.5 m apart, offset so that no car stands exactly on the grid
  options.x_max_m = 9.3;
  options.y_min_m = 7.7;
  options.y_max_m = 13.3;
  options.step_m = 0.5;
  options.yaws_deg = {0,  30,  60,
                      90, 120, 150};  // cars are nearly symmetric front to back (0, 60, 120 misses the van)
  return options;
}

// A sweep over the whole lot with the sedan's and with the van's model finds that car and nothing else at the
// default thresholds (grid 0.5 m x 30°, then local refinement).
TEST_F(ParkingLotTest, SweepWithTheSedanAndVanModelsFindsEachCarOnly) {
  for (const Car& car : {kCars[0], kCars[2]}) {
    CarMeshOptions mesh_options;
    mesh_options.style = ParseCarStyle(car.style, "test");
    const VerifierModel model = PrepareModel(MakeCarMesh(mesh_options));
    const SweepResult sweep = Sweep(model, *scans_, CarSweep(), VerifyOptions());
    const VerifyResult truth = VerifyPose(model, *scans_, PoseFromXyzYaw(car.x, car.y, 0, car.yaw_deg));
    std::string found;
    for (const Detection& d : sweep.detections) {
      found += fmt::format(" ({:.2f}, {:.2f}, {:.1f}°: consistency {:.3f} confidence {:.3f})", d.x_m, d.y_m,
                           d.yaw_deg, d.consistency, d.confidence);
    }
    fmt::print("{}: truth {}; {} refined seeds, {} detections:{}\n", car.style, truth.BriefReport(),
               sweep.refined.size(), sweep.detections.size(), found);
    SCOPED_TRACE(car.style + ":" + found);
    ASSERT_EQ(sweep.detections.size(), 1u);
    const Detection& d = sweep.detections[0];
    EXPECT_LT(std::hypot(d.x_m - car.x, d.y_m - car.y), 0.3);
    // Cars are nearly symmetric front to back: either heading is right.
    EXPECT_LE(std::abs(std::remainder(d.yaw_deg - car.yaw_deg, 180.0)), 5.0);
  }
}

// The known weakness (bench/results/verify.md): the hatchback is seen from one side only (confidence 0.24 at
// its true pose, under the 0.3 threshold), while its smaller model fits inside the sedan, where it is
// consistent and, the sedan's sides being close to its own, partly "seen": a smaller model is consistent with
// a larger vehicle.
TEST_F(ParkingLotTest, SmallerHatchbackModelIsConsistentInsideTheSedanMoreThanTheReverse) {
  CarMeshOptions hatchback_options, sedan_options;
  hatchback_options.style = CarStyle::kHatchback;
  const VerifierModel hatchback = PrepareModel(MakeCarMesh(hatchback_options));
  const VerifierModel sedan = PrepareModel(MakeCarMesh(sedan_options));
  const VerifyResult hatchback_at_sedan = VerifyPose(hatchback, *scans_, PoseFromXyzYaw(-6.5, 10, 0, 90));
  const VerifyResult sedan_at_hatchback = VerifyPose(sedan, *scans_, PoseFromXyzYaw(0, 11, 0, -90));
  const VerifyResult hatchback_truth = VerifyPose(hatchback, *scans_, PoseFromXyzYaw(0, 11, 0, -90));
  SCOPED_TRACE("hatchback at sedan: " + hatchback_at_sedan.BriefReport() + "\nsedan at hatchback: " +
               sedan_at_hatchback.BriefReport() + "\nhatchback truth: " + hatchback_truth.BriefReport());
  EXPECT_GT(hatchback_at_sedan.consistency, 0.75);
  // The reverse is less consistent (the sedan's 30 cm overhangs at each end go through the ground seen behind
  // the hatchback) — but from a single side view only 0.85, not near 0 as with four scans
  // (verify_multiscan_test).
  EXPECT_LT(sedan_at_hatchback.consistency, hatchback_at_sedan.consistency);
  EXPECT_LT(sedan_at_hatchback.consistency, 0.9);
  EXPECT_GT(hatchback_truth.consistency, 0.99);
  EXPECT_LT(hatchback_truth.confidence, 0.3);
}

TEST_F(ParkingLotTest, HalfwayBetweenTwoCarsIsRejectedByConsistencyNotByIcp) {
  const VerifierModel model = PrepareModel(MakePrimitive("car", R"({"style": "sedan"})"));
  const VerifyResult truth = VerifyPose(model, *scans_, PoseFromXyzYaw(-6.5, 10, 0, 90));
  const VerifyResult halfway = VerifyPose(model, *scans_, PoseFromXyzYaw(-3.25, 10.5, 0, 90));
  SCOPED_TRACE("truth: " + truth.BriefReport() + "\nhalfway: " + halfway.BriefReport());
  EXPECT_GT(truth.consistency, 0.9);
  ASSERT_TRUE(halfway.has_comparable_pairs);
  EXPECT_LT(halfway.consistency, 0.3);
  // The trimmed ICP cost does not reject it: 0.13 m, inside the 0.2 m trim, with ~74 % inliers (truth 0.05
  // m).
  EXPECT_LT(halfway.icp_cost_m, VerifyOptions().icp_trim_m);
  EXPECT_GT(halfway.inlier_fraction, 0.5);
}

}  // namespace
}  // namespace lidarshop
