// The built-in parking lot (data/scenes/parking_lot.json: a sedan, a hatchback and a van in angled bays, each
// showing the scanner one end and one side, 4 mm range noise, one scanner): a sweep with each car model finds
// that car and nothing else at the default thresholds, and a pose halfway between two cars is rejected by
// consistency while its trimmed ICP cost stays inside the trim.
#include <chrono>
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
const std::vector<Car> kCars = {{"sedan", 6.5, 10, 120}, {"hatchback", 0, 11, 120}, {"van", -6.5, 10.5, 80}};

class ParkingLotTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const SceneDescription scene = test_scenes::LoadBuiltinScene("parking_lot");
    // The built-in 960 x 560 scan (0.125° steps: ≈ 2.2 cm at 10 m).
    scans_ = new std::vector<PreparedScan>{PrepareScan(test_scenes::ScanScene(scene))};
    models_ = new std::vector<VerifierModel>;
    for (const Car& car : kCars) {
      CarMeshOptions mesh_options;
      mesh_options.style = ParseCarStyle(car.style, "test");
      models_->push_back(PrepareModel(MakeCarMesh(mesh_options)));
    }
  }
  static void TearDownTestSuite() {
    delete scans_;
    delete models_;
  }
  static std::vector<PreparedScan>* scans_;
  static std::vector<VerifierModel>* models_;
};
std::vector<PreparedScan>* ParkingLotTest::scans_ = nullptr;
std::vector<VerifierModel>* ParkingLotTest::models_ = nullptr;

SweepOptions CarSweep() {
  SweepOptions options;
  // The row of bays (car centres at y 10–11 m, x within ±6.5 m) with 2.3 m to spare around them; positions
  // 0.5 m apart, offset so that no car stands exactly on the grid.
  options.x_min_m = -8.8;
  options.x_max_m = 8.8;
  options.y_min_m = 8.2;
  options.y_max_m = 12.7;
  options.step_m = 0.5;
  // Half a turn: every car's true yaw lies in [0°, 180°); the cars are nearly symmetric front to back, so the
  // test accepts either heading (the other half would double the run time).
  options.yaws_deg = {0, 30, 60, 90, 120, 150};
  return options;
}

// Each model at each car's true pose: its own car passes both thresholds, the others fail at least one.
TEST_F(ParkingLotTest, EachModelPassesOnlyAtItsOwnCar) {
  const SweepOptions thresholds;
  for (size_t m = 0; m < kCars.size(); ++m) {
    for (size_t c = 0; c < kCars.size(); ++c) {
      const VerifyResult r =
          VerifyPose((*models_)[m], *scans_, PoseFromXyzYaw(kCars[c].x, kCars[c].y, 0, kCars[c].yaw_deg));
      fmt::print("{} model at the {}: {}\n", kCars[m].style, kCars[c].style, r.BriefReport());
      SCOPED_TRACE(kCars[m].style + " model at the " + kCars[c].style + ": " + r.BriefReport());
      const bool passes =
          r.consistency > thresholds.min_consistency && r.confidence > thresholds.min_confidence;
      if (m == c) {
        EXPECT_GT(r.consistency, 0.99);
        EXPECT_TRUE(passes);
      } else {
        EXPECT_FALSE(passes);
      }
    }
  }
}

// A sweep over the whole lot with each car's model finds that car and nothing else at the default thresholds
// (grid 0.5 m x 30°, then local refinement).
TEST_F(ParkingLotTest, SweepWithEachCarModelFindsThatCarOnly) {
  for (size_t m = 0; m < kCars.size(); ++m) {
    const Car& car = kCars[m];
    const auto start = std::chrono::steady_clock::now();
    const SweepResult sweep = Sweep((*models_)[m], *scans_, CarSweep(), VerifyOptions());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::string found;
    for (const Detection& d : sweep.detections) {
      found += fmt::format(" ({:.2f}, {:.2f}, {:.1f}°: consistency {:.3f} confidence {:.3f})", d.x_m, d.y_m,
                           d.yaw_deg, d.consistency, d.confidence);
    }
    fmt::print(
        "{}: {} grid poses + {} refinement poses ({:.1f} s wall), {} refined seeds, {} detections:{}\n",
        car.style, sweep.poses.size(), sweep.refine_evaluations, seconds, sweep.refined.size(),
        sweep.detections.size(), found);
    SCOPED_TRACE(car.style + ":" + found);
    ASSERT_EQ(sweep.detections.size(), 1u);
    const Detection& d = sweep.detections[0];
    EXPECT_LT(std::hypot(d.x_m - car.x, d.y_m - car.y), 0.3);
    // Cars are nearly symmetric front to back: either heading is accepted.
    EXPECT_LE(std::abs(std::remainder(d.yaw_deg - car.yaw_deg, 180.0)), 5.0);
  }
}

TEST_F(ParkingLotTest, HalfwayBetweenTwoCarsIsRejectedByConsistencyNotByIcp) {
  const VerifierModel& sedan = (*models_)[0];
  const VerifyResult truth = VerifyPose(sedan, *scans_, PoseFromXyzYaw(kCars[0].x, kCars[0].y, 0, 120));
  // Halfway between the sedan (6.5, 10) and the hatchback (0, 11).
  const VerifyResult halfway = VerifyPose(sedan, *scans_, PoseFromXyzYaw(3.25, 10.5, 0, 120));
  fmt::print("sedan model: truth {}\nhalfway {}\n", truth.BriefReport(), halfway.BriefReport());
  SCOPED_TRACE("truth: " + truth.BriefReport() + "\nhalfway: " + halfway.BriefReport());
  EXPECT_GT(truth.consistency, 0.9);
  ASSERT_TRUE(halfway.has_comparable_pairs);
  EXPECT_LT(halfway.consistency, 0.3);
  // The trimmed ICP cost does not reject it: inside the 0.2 m trim, with most scene points near the model
  // counted as inliers.
  EXPECT_LT(halfway.icp_cost_m, VerifyOptions().icp_trim_m);
  EXPECT_GT(halfway.inlier_fraction, 0.5);
}

}  // namespace
}  // namespace lidarshop
