// Registration of a whole site (pointset/site_registration.h) on a synthetic courtyard whose true poses are
// known: five stations with poses spoiled by 2° and 0.5 m come back within 5 mm and 0.02°.
#include "lidarshop/pointset/site_registration.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A walled courtyard (30 x 24 m, 4 m walls) with boxes, a cylinder and a sphere at several angles, so that
// every pair of stations constrains all six degrees of freedom.
constexpr char kCourtyard[] = R"({"objects": [
  {"primitive": "plane", "size": [40, 40]},
  {"primitive": "box", "size": [30, 0.4, 4], "translate": [0, 12, 2]},
  {"primitive": "box", "size": [30, 0.4, 4], "translate": [0, -12, 2]},
  {"primitive": "box", "size": [0.4, 24, 4], "translate": [15, 0, 2]},
  {"primitive": "box", "size": [0.4, 24, 4], "translate": [-15, 0, 2]},
  {"primitive": "box", "size": [2, 1, 1.5], "rotate_deg": [0, 0, 25], "translate": [-3, 2, 0.75]},
  {"primitive": "box", "size": [1.5, 1.5, 2.5], "rotate_deg": [0, 0, -40], "translate": [4, -1, 1.25]},
  {"primitive": "box", "size": [3, 0.6, 1], "rotate_deg": [0, 0, 70], "translate": [9, 6, 0.5]},
  {"primitive": "box", "size": [1, 1, 1], "rotate_deg": [20, 30, 10], "translate": [-9, -4, 1.2]},
  {"primitive": "cylinder", "radius": 0.4, "height": 3, "translate": [1, 7, 1.5]},
  {"primitive": "sphere", "radius": 0.8, "segments": 48, "translate": [-6, 8, 0.8]}]})";

ScannerOptions Station(const Eigen::Vector3d& position, double yaw_deg, uint64_t seed) {
  ScannerOptions options;
  options.position = position;
  options.rotate_deg = Eigen::Vector3d(0, 0, yaw_deg);
  options.azimuth_min_deg = -180;
  options.azimuth_max_deg = 179.5;
  options.elevation_min_deg = -45;
  options.elevation_max_deg = 40;
  options.columns = 720;
  options.rows = 170;
  options.los_noise_sigma_m = 0.002;
  options.seed = seed;
  return options;
}

struct PoseError {
  double translation_m = 0, rotation_deg = 0;
};
PoseError Error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth) {
  const Eigen::Matrix3d rotation = estimate.topLeftCorner<3, 3>() * truth.topLeftCorner<3, 3>().transpose();
  return {(estimate.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(),
          std::acos(std::clamp((rotation.trace() - 1) / 2, -1.0, 1.0)) * 180 / M_PI};
}

// `pose` turned by `angle_deg` about a random axis through its origin and moved by `offset_m` in a random
// direction.
Eigen::Matrix4d Spoiled(const Eigen::Matrix4d& pose, double angle_deg, double offset_m,
                        std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
  const Eigen::Vector3d direction = Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
  Eigen::Matrix4d out = pose;
  out.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(angle_deg * M_PI / 180, axis).matrix() * pose.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() += offset_m * direction;
  return out;
}

class SiteRegistrationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const SceneDescription scene = ParseScene(kCourtyard, "courtyard", "");
    const SyntheticScanner scanner(scene);
    const std::vector<ScannerOptions> stations = {
        Station({-8, -6, 1.5}, 10, 1), Station({0, -7, 1.6}, -20, 2), Station({8, -5, 1.4}, 45, 3),
        Station({7, 5, 1.5}, 160, 4), Station({-7, 6, 1.7}, -120, 5)};
    for (const ScannerOptions& options : stations) {
      truth_->push_back(options.WorldFromScanner());
      scans_->push_back(scanner.Acquire(options));
    }
  }
  static inline std::vector<Scan>* scans_ = new std::vector<Scan>;
  static inline std::vector<Eigen::Matrix4d>* truth_ = new std::vector<Eigen::Matrix4d>;
};

TEST_F(SiteRegistrationTest, FiveSpoiledStationsComeBackWithin5MmAnd002Degrees) {
  std::mt19937_64 rng(7);
  std::vector<Scan> spoiled = *scans_;
  for (size_t k = 1; k < spoiled.size(); ++k) {
    spoiled[k].world_from_scanner = Spoiled((*truth_)[k], 2.0, 0.5, &rng);
    const PoseError before = Error(spoiled[k].world_from_scanner, (*truth_)[k]);
    ASSERT_NEAR(before.translation_m, 0.5, 1e-9);
    ASSERT_NEAR(before.rotation_deg, 2.0, 1e-6);
  }
  const SiteRegistration result = RegisterSite(spoiled, 0, IcpOptions{}, SiteRegistrationOptions{});
  ASSERT_EQ(result.stations.size(), 5u);
  EXPECT_EQ(result.stations[0].world_from_scanner, (*truth_)[0]);  // the fixed station stays
  double worst_m = 0, worst_deg = 0;
  for (size_t k = 1; k < 5; ++k) {
    const PoseError error = Error(result.stations[k].world_from_scanner, (*truth_)[k]);
    worst_m = std::max(worst_m, error.translation_m);
    worst_deg = std::max(worst_deg, error.rotation_deg);
    EXPECT_NEAR(result.stations[k].moved_m, 0.5, 0.01) << k;
    EXPECT_GE(result.stations[k].pairs, 2) << k;  // a loop, not a chain
    EXPECT_LT(result.stations[k].rms_m, 0.01) << k;
  }
  std::printf("worst station error: %.2f mm, %.4f deg; %zu pairs, graph %d iterations\n", worst_m * 1e3,
              worst_deg, result.pairs.size(), result.graph_iterations);
  EXPECT_LT(worst_m, 0.005);
  EXPECT_LT(worst_deg, 0.02);
  int in_graph = 0;
  for (const SitePair& pair : result.pairs) {
    in_graph += pair.in_graph;
    if (pair.in_graph) EXPECT_LT(pair.graph_translation_m, 0.01) << pair.a << "-" << pair.b;
  }
  EXPECT_GE(in_graph, 5);  // more pairs than a spanning tree (4): the loop closes
}

TEST(PoseGraph, SpreadsALoopsErrorAndHoldsTheFixedStation) {
  // Four poses on a square; the measurements agree except one, off by 4 cm: the graph spreads the
  // disagreement over the loop (each pair 0.5-1.5 cm; rotations take a part) instead of leaving it on one pair.
  std::vector<Eigen::Matrix4d> truth(4, Eigen::Matrix4d::Identity());
  truth[1].topRightCorner<3, 1>() = Eigen::Vector3d(10, 0, 0);
  truth[2].topRightCorner<3, 1>() = Eigen::Vector3d(10, 10, 0);
  truth[3].topRightCorner<3, 1>() = Eigen::Vector3d(0, 10, 0);
  std::vector<SitePair> pairs;
  for (auto [a, b] : std::vector<std::pair<int, int>>{{0, 1}, {1, 2}, {2, 3}, {0, 3}}) {
    SitePair pair;
    pair.a = a;
    pair.b = b;
    pair.in_graph = true;
    pair.a_from_b_measured = truth[a].inverse() * truth[b];
    pairs.push_back(pair);
  }
  pairs[2].a_from_b_measured(0, 3) += 0.04;
  std::vector<Eigen::Matrix4d> poses = truth;
  poses[2](1, 3) += 0.3;  // a poor start
  const int iterations = OptimizePoseGraph(&poses, &pairs, 0, SiteRegistrationOptions{});
  EXPECT_GE(iterations, 1);
  EXPECT_EQ(poses[0], truth[0]);
  for (const SitePair& pair : pairs) {
    EXPECT_GT(pair.graph_translation_m, 0.005) << pair.a << "-" << pair.b;
    EXPECT_LT(pair.graph_translation_m, 0.015) << pair.a << "-" << pair.b;
  }
  // Without the loop's last pair the chain is consistent: every pair agrees exactly.
  pairs[3].in_graph = false;
  poses = truth;
  OptimizePoseGraph(&poses, &pairs, 0, SiteRegistrationOptions{});
  for (int k = 0; k < 3; ++k) EXPECT_LT(pairs[k].graph_translation_m, 1e-9) << k;
}

TEST(SiteRegistration, RefusesASingleStationAndABadFixedIndex) {
  std::vector<Scan> one(1);
  EXPECT_THROW(RegisterSite(one, 0, IcpOptions{}, SiteRegistrationOptions{}), OptionsError);
  std::vector<Scan> two(2);
  EXPECT_THROW(RegisterSite(two, 2, IcpOptions{}, SiteRegistrationOptions{}), OptionsError);
}

}  // namespace
}  // namespace lidarshop
