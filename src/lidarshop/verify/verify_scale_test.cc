// A model in other units: a uniform scale in world_from_model, the mesh pre-scaled and
// ModelOptions::model_scale must give the same consistency, confidence and ICP cost, with σ, the trim
// distance and the allowance in world metres in every case.
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/verify/verify.h"
#include "lidarshop/verify/verify_test_util.h"

namespace lidarshop {
namespace {

using verify_testing::LabeledMesh;
using verify_testing::MakeCar;
using verify_testing::SyntheticScan;

TriangleMesh Scaled(const TriangleMesh& mesh, double scale) {
  TriangleMesh scaled = mesh;
  for (Eigen::Vector3f& v : scaled.vertices) v = (v.cast<double>() * scale).cast<float>();
  return scaled;
}

Eigen::Matrix4d WithScale(const Eigen::Matrix4d& pose, double scale) {
  Eigen::Matrix4d scaled = pose;
  scaled.topLeftCorner<3, 3>() *= scale;
  return scaled;
}

// A car in metres standing at (0, 10, 0), yawed 30° so that the scanner at (0, 0, 1.5) sees a side and an
// end, on a ground slab; its model is given in units of `metres_per_unit`.
class VerifyScaleTest : public ::testing::TestWithParam<double> {
 protected:
  void SetUp() override {
    world_from_object_ = PoseFromXyzYaw(0, 10, 0, 30);
    const std::vector<LabeledMesh> meshes = {
        {TransformMesh(car_in_metres_, world_from_object_), 1},
        {verify_testing::MakeBox(Eigen::Vector3f(-30, -5, -0.2f), Eigen::Vector3f(30, 40, 0.0f)), 2}};
    scans_ = {PrepareScan(SyntheticScan(meshes, PoseFromXyzYaw(0, 0, 1.5, 0), 151, 301, -20, 20, -15, 5))};
  }

  TriangleMesh car_in_metres_ = MakeCar();
  Eigen::Matrix4d world_from_object_;
  std::vector<PreparedScan> scans_;
};

void ExpectSameMeasures(const VerifyResult& a, const VerifyResult& b) {
  EXPECT_NEAR(a.consistency, b.consistency, 1e-3);
  EXPECT_NEAR(static_cast<double>(a.comparable_pairs), static_cast<double>(b.comparable_pairs),
              1e-3 * static_cast<double>(b.comparable_pairs) + 2);
  EXPECT_NEAR(a.confidence, b.confidence, 2e-4);
  if (std::isnan(b.icp_cost_m)) {
    EXPECT_TRUE(std::isnan(a.icp_cost_m));
  } else {
    EXPECT_NEAR(a.icp_cost_m, b.icp_cost_m, 1e-5);  // metres
  }
  EXPECT_NEAR(a.inlier_fraction, b.inlier_fraction, 1e-3);
  EXPECT_NEAR(static_cast<double>(a.icp_candidates), static_cast<double>(b.icp_candidates),
              1e-3 * static_cast<double>(b.icp_candidates) + 2);
}

TEST_P(VerifyScaleTest, ScaleInThePoseEqualsThePreScaledMesh) {
  const double metres_per_unit = GetParam();
  const TriangleMesh car_in_units = Scaled(car_in_metres_, 1.0 / metres_per_unit);

  const VerifierModel in_units = PrepareModel(car_in_units);  // the scale goes into the pose
  const VerifierModel pre_scaled = PrepareModel(Scaled(car_in_units, metres_per_unit));
  ModelOptions model_options;
  model_options.model_scale = metres_per_unit;
  const VerifierModel by_option = PrepareModel(car_in_units, model_options);
  EXPECT_NEAR(by_option.bounds_in_model.max().x(), 2.25f, 1e-5f);
  EXPECT_NEAR(by_option.surface_area_m2, pre_scaled.surface_area_m2, 1e-4 * pre_scaled.surface_area_m2);

  Eigen::Vector3d towards_scanner = -world_from_object_.topRightCorner<3, 1>();
  towards_scanner.z() = 0;
  towards_scanner.normalize();
  Eigen::Matrix4d offset = world_from_object_;
  offset.topRightCorner<3, 1>() += towards_scanner;  // 1 m towards the scanner: in front of the seen surface

  for (const Eigen::Matrix4d& pose : {world_from_object_, offset}) {
    const VerifyResult scaled_pose = VerifyPose(in_units, scans_, WithScale(pose, metres_per_unit));
    const VerifyResult reference = VerifyPose(pre_scaled, scans_, pose);
    const VerifyResult option = VerifyPose(by_option, scans_, pose);
    SCOPED_TRACE(reference.BriefReport());
    ExpectSameMeasures(scaled_pose, reference);
    ExpectSameMeasures(option, reference);
  }

  // The measures are those of metres: the true pose passes, the offset one fails, whichever way (with σ in
  // model units the millimetre model saw nothing and the tenths model everything).
  const VerifyResult truth = VerifyPose(pre_scaled, scans_, world_from_object_);
  EXPECT_GT(truth.consistency, 0.95);
  EXPECT_GT(truth.confidence, 0.2);  // one side and one end of a car (0.28)
  EXPECT_LT(truth.confidence, 0.5);
  EXPECT_LT(truth.icp_cost_m, 0.04);  // noise-free; the ground under the sill is within the trim distance
  const VerifyResult wrong = VerifyPose(pre_scaled, scans_, offset);
  EXPECT_LT(wrong.consistency, 0.5);
  EXPECT_LT(wrong.confidence, 0.7 * truth.confidence);
  EXPECT_GT(wrong.icp_cost_m, 2 * truth.icp_cost_m);
  for (const VerifyResult& result :
       {VerifyPose(in_units, scans_, WithScale(world_from_object_, metres_per_unit)),
        VerifyPose(by_option, scans_, world_from_object_)}) {
    EXPECT_NEAR(result.confidence, truth.confidence, 2e-4);
    EXPECT_GT(result.consistency, 0.95);
  }
  for (const VerifyResult& result : {VerifyPose(in_units, scans_, WithScale(offset, metres_per_unit)),
                                     VerifyPose(by_option, scans_, offset)}) {
    EXPECT_LT(result.consistency, 0.5);
    EXPECT_LT(result.confidence, 0.7 * truth.confidence);
  }
}

// Millimetres (the σ of 5 cm was 50 µm before) and a model ten times too small (σ was 50 cm).
INSTANTIATE_TEST_SUITE_P(Units, VerifyScaleTest, ::testing::Values(0.001, 10.0, 1.0));

TEST(VerifyScaleTest, RejectsPosesThatAreNotARotationTimesOneScale) {
  const VerifierModel model = PrepareModel(MakeCar());
  const std::vector<PreparedScan> scans = {
      PrepareScan(SyntheticScan({{MakeCar(), 1}}, PoseFromXyzYaw(0, -10, 1, 0), 11, 11, -10, 10, -10, 10))};
  Eigen::Matrix4d stretched = Eigen::Matrix4d::Identity();
  stretched(0, 0) = 2.0;
  EXPECT_THROW(VerifyPose(model, scans, stretched), std::invalid_argument);
  Eigen::Matrix4d mirrored = Eigen::Matrix4d::Identity();
  mirrored(2, 2) = -1.0;
  EXPECT_THROW(VerifyPose(model, scans, mirrored), std::invalid_argument);
  ModelOptions bad;
  bad.model_scale = 0.0;
  EXPECT_THROW(PrepareModel(MakeCar(), bad), OptionsError);
}

}  // namespace
}  // namespace lidarshop
