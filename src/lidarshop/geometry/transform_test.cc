#include "lidarshop/geometry/transform.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace lidarshop {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Rz(yaw) · Ry(pitch) · Rx(roll) as three matrix products of Eigen's elementary rotations, written out
// independently of RotationFromEulerDegrees (which multiplies quaternions).
Eigen::Matrix3d ZyxFromAngleAxis(double roll_deg, double pitch_deg, double yaw_deg) {
  const Eigen::Matrix3d rz =
      Eigen::AngleAxisd(yaw_deg * kDegree, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d ry =
      Eigen::AngleAxisd(pitch_deg * kDegree, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d rx =
      Eigen::AngleAxisd(roll_deg * kDegree, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return rz * ry * rx;
}

TEST(RotationFromEuler, MatchesRzRyRxForRandomAngles) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> angle(-360.0, 360.0);
  for (int i = 0; i < 1000; ++i) {
    const double roll = angle(random), pitch = angle(random), yaw = angle(random);
    const Eigen::Matrix3d rotation = RotationFromEulerDegrees({roll, pitch, yaw});
    EXPECT_LT((rotation - ZyxFromAngleAxis(roll, pitch, yaw)).cwiseAbs().maxCoeff(), 1e-12)
        << "roll " << roll << " pitch " << pitch << " yaw " << yaw;
    EXPECT_NEAR(rotation.determinant(), 1.0, 1e-12);
  }
}

TEST(RotationFromEuler, NamedAxesAndOrder) {
  const auto near = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm() < 1e-12; };
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  // Yaw about z turns +x towards +y; pitch about y turns +z towards +x; roll about x turns +y towards +z.
  EXPECT_TRUE(near(RotationFromEulerDegrees({0, 0, 90}) * x, y));
  EXPECT_TRUE(near(RotationFromEulerDegrees({0, 90, 0}) * z, x));
  EXPECT_TRUE(near(RotationFromEulerDegrees({90, 0, 0}) * y, z));
  // Roll is applied first: roll 90 takes +y to +z, which yaw then leaves alone; applied last (the other
  // order) +y would go to -x first and end at -x.
  EXPECT_TRUE(near(RotationFromEulerDegrees({90, 0, 90}) * y, z));
}

TEST(RotationFromEuler, ComposeTransformUsesIt) {
  const Eigen::Matrix4d transform = ComposeTransform({1, 2, 3}, {10, -20, 30}, {2, 2, 2});
  const Eigen::Matrix3d linear = transform.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = transform.topRightCorner<3, 1>();
  EXPECT_TRUE(linear.isApprox(RotationFromEulerDegrees({10, -20, 30}) * 2.0, 1e-15));
  EXPECT_EQ(translation, Eigen::Vector3d(1, 2, 3));
}

}  // namespace
}  // namespace lidarshop
