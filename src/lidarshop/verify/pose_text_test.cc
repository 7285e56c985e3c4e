#include "lidarshop/verify/pose_text.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {
namespace {

// The rotation PoseFromXyzYaw built before it used RotationFromEulerDegrees: Rz(yaw) · Rx(pitch) · Ry(roll)
// (pitch about x, roll about y), as the same quaternion product. Kept here to show which results changed.
Eigen::Matrix3d FormerPoseRotation(double yaw_deg, double pitch_deg, double roll_deg) {
  const double to_rad = M_PI / 180.0;
  return (Eigen::AngleAxisd(yaw_deg * to_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * to_rad, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll_deg * to_rad, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

TEST(PoseFromXyzYaw, IsTheGeometryRotationPlusTranslation) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-180.0, 180.0), position(-50.0, 50.0);
  for (int i = 0; i < 200; ++i) {
    const double x = position(random), y = position(random), z = position(random);
    const double yaw = angle(random), pitch = angle(random), roll = angle(random);
    const Eigen::Matrix4d pose = PoseFromXyzYaw(x, y, z, yaw, pitch, roll);
    EXPECT_EQ(Eigen::Matrix3d(pose.topLeftCorner<3, 3>()), RotationFromEulerDegrees({roll, pitch, yaw}));
    EXPECT_EQ(Eigen::Vector3d(pose.topRightCorner<3, 1>()), Eigen::Vector3d(x, y, z));
    EXPECT_EQ(Eigen::RowVector4d(pose.row(3)), Eigen::RowVector4d(0, 0, 0, 1));
  }
}

TEST(PoseFromXyzYaw, YawOnlyPosesAreBitIdenticalToTheFormerConvention) {
  for (double yaw = -720.0; yaw <= 720.0; yaw += 0.37) {
    const Eigen::Matrix3d rotation = PoseFromXyzYaw(1, 2, 3, yaw).topLeftCorner<3, 3>();
    const Eigen::Matrix3d former = FormerPoseRotation(yaw, 0, 0);
    for (int k = 0; k < 9; ++k) ASSERT_EQ(rotation(k), former(k)) << "yaw " << yaw;
  }
}

TEST(PoseFromXyzYaw, PitchAndRollNowTurnAboutYAndX) {
  // Pitch 90 turns the model's +z towards +x (about y); the former convention turned it towards -y (about x).
  const Eigen::Matrix3d pitched = PoseFromXyzYaw(0, 0, 0, 0, 90, 0).topLeftCorner<3, 3>();
  EXPECT_TRUE((pitched * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_FALSE((FormerPoseRotation(0, 90, 0) * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX()));
  // Roll 90 turns +y towards +z (about x).
  const Eigen::Matrix3d rolled = PoseFromXyzYaw(0, 0, 0, 0, 0, 90).topLeftCorner<3, 3>();
  EXPECT_TRUE((rolled * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

class PoseFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("lidarshop_pose_text_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (folder_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path folder_;
};

TEST_F(PoseFileTest, EveryFormGivesTheSamePose) {
  const Eigen::Matrix4d expected = PoseFromXyzYaw(1.5, -2, 0.25, 30, 10, -5);
  std::string sixteen;
  for (int i = 0; i < 16; ++i) sixteen += fmt::format("{}{:.17g}", i ? "," : "", expected(i / 4, i % 4));
  EXPECT_EQ(ParsePose("1.5,-2,0.25,30,10,-5"), expected);
  EXPECT_EQ(ParsePose(sixteen), expected);
  std::string rows;
  for (int r = 0; r < 4; ++r) {
    rows += fmt::format("{:.17g} {:.17g} {:.17g} {:.17g}\n", expected(r, 0), expected(r, 1), expected(r, 2),
                        expected(r, 3));
  }
  EXPECT_EQ(ParsePose(Write("pose.txt", rows)), expected);
  EXPECT_EQ(ParsePose(Write("angles.json", R"({"x_m": 1.5, "y_m": -2, "z_m": 0.25, "yaw_deg": 30,
                                               "pitch_deg": 10, "roll_deg": -5})")),
            expected);
  nlohmann::json matrix = {{"world_from_model", nlohmann::json::array()}};
  for (int r = 0; r < 4; ++r) {
    matrix["world_from_model"].push_back({expected(r, 0), expected(r, 1), expected(r, 2), expected(r, 3)});
  }
  EXPECT_EQ(ParsePose(Write("matrix.json", matrix.dump())), expected);
  EXPECT_EQ(ParsePose("0,5,0,90"), PoseFromXyzYaw(0, 5, 0, 90));
}

TEST_F(PoseFileTest, BadPosesGiveOneLineNamingTheSource) {
  const auto message = [](const std::function<void()>& parse) {
    try {
      parse();
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no InputError");
  };
  EXPECT_EQ(
      message([] { ParsePose("1,2", "--matrix"); }),
      "--matrix: expected a file of 4x4 numbers, 16 numbers or x,y,z,yaw_deg[,pitch_deg,roll_deg], got 2 "
      "numbers");
  EXPECT_EQ(
      message([] { ParsePose("2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1"); }),
      "--pose: world_from_model is sheared or scaled per axis (the 3x3 part is not a rotation times one "
      "scale)");
  const std::string bad_key = Write("bad_key.json", R"({"x_m": 1, "yaw": 90})");
  EXPECT_EQ(message([&] { ParsePose(bad_key); }),
            bad_key + ": yaw: unknown key (x_m, y_m, z_m, yaw_deg, pitch_deg, roll_deg or world_from_model)");
  const std::string not_json = Write("broken.json", "{\"x_m\": ");
  EXPECT_NE(message([&] { ParsePose(not_json); }).find(not_json + ": not JSON"), std::string::npos);
  // A number past double's range is nlohmann's out_of_range, not a parse_error: it ended the process
  // (found by pose_fuzz).
  const std::string overflow = Write("overflow.json", R"({"x_m": 0.0157e886661})");
  EXPECT_NE(message([&] { ParsePose(overflow); }).find(overflow + ": not JSON"), std::string::npos);
  const std::string mirrored =
      Write("mirror.json", R"({"world_from_model": [[-1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})");
  EXPECT_EQ(message([&] { ParsePose(mirrored); }),
            mirrored + ": world_from_model: is mirrored (determinant < 0)");
}

TEST(PoseFromJson, NamesTheKeyOfABadValue) {
  const auto reason = [](const nlohmann::json& pose) {
    try {
      PoseFromJson(pose);
    } catch (const OptionsFieldError& error) {
      return error.key_path() + ": " + error.reason();
    }
    return std::string("no error");
  };
  EXPECT_EQ(reason({{"x_m", "left"}}), "x_m: expected a number, got \"left\"");
  EXPECT_EQ(reason({{"y_m", 1e300}}), "y_m: beyond 10000000 m");
  EXPECT_EQ(reason(nlohmann::json::array()), "pose: expected an object, got []");
  EXPECT_EQ(reason({{"world_from_model", {{1, 0, 0}}}}), "world_from_model: expected 4 rows of 4 numbers");
  EXPECT_EQ(reason({{"world_from_model", nlohmann::json::array()}, {"x_m", 1}}),
            "world_from_model: give either world_from_model or x_m, y_m, z_m and angles");
  EXPECT_EQ(PoseFromJson(nlohmann::json::object()), Eigen::Matrix4d::Identity());
  EXPECT_EQ(PoseFromJson({{"yaw_deg", 90}, {"z_m", 2}}), PoseFromXyzYaw(0, 0, 2, 90));
}

}  // namespace
}  // namespace lidarshop
