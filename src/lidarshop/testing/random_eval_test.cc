#include "lidarshop/testing/random_eval.h"

#include <gtest/gtest.h>

#include "lidarshop/util/error.h"

namespace lidarshop::test_scenes {
namespace {

TEST(ParseSeedRange, RangesAndCounts) {
  EXPECT_EQ(ParseSeedRange("3..6"), (std::vector<uint64_t>{3, 4, 5, 6}));
  EXPECT_EQ(ParseSeedRange("3"), (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(ParseSeedRange("7..7"), (std::vector<uint64_t>{7}));
  for (const char* bad : {"", "0", "6..3", "a..b", "1..", "..4", "-2", "1..2x", "1..999999"}) {
    EXPECT_THROW(ParseSeedRange(bad), OptionsError) << bad;
  }
}

TEST(Distribute, MeanPercentilesAndWorst) {
  std::vector<double> values;
  std::vector<uint64_t> seeds;
  for (int i = 1; i <= 20; ++i) {  // 20 values 0.05 .. 1.00, seed 100 + i
    values.push_back(i / 20.0);
    seeds.push_back(100 + i);
  }
  const SeedDistribution up = Distribute(values, seeds, true);
  EXPECT_NEAR(up.mean, 0.525, 1e-12);
  EXPECT_DOUBLE_EQ(up.p5, 0.05);   // the 1st of 20
  EXPECT_DOUBLE_EQ(up.p95, 0.95);  // the 19th of 20
  EXPECT_DOUBLE_EQ(up.worst, 0.05);
  EXPECT_EQ(up.worst_seed, 101u);
  const SeedDistribution down = Distribute(values, seeds, false);
  EXPECT_DOUBLE_EQ(down.worst, 1.0);
  EXPECT_EQ(down.worst_seed, 120u);
  EXPECT_EQ(WorstIndices(values, 3, false), (std::vector<size_t>{19, 18, 17}));
  EXPECT_EQ(WorstIndices({0.5, 0.2, 0.2}, 5, true), (std::vector<size_t>{1, 2, 0}));
  EXPECT_THROW(Distribute({}, {}, true), std::logic_error);
}

TEST(TargetDescription, KindDistanceAndColourLikeTheBackground) {
  SceneDescription scene = ParseScene(
      R"({"target_label": 2, "objects": [
          {"name": "ground_1", "primitive": "plane", "size": [20, 20], "label": 1, "color": [90, 110, 70]},
          {"name": "bin_2/body", "primitive": "box", "translate": [3, 4, 0.5], "label": 2, "color": [200, 0, 0]},
          {"name": "bin_2/lid", "primitive": "box", "translate": [3, 4, 1.5], "label": 2, "color": [1, 2, 3]}]})",
      "t.json", "");
  scene.scanner.position = Eigen::Vector3d(0, 0, 1.5);
  EXPECT_EQ(TargetKind(scene), "bin");
  EXPECT_NEAR(TargetDistance(scene), 5.0, 1e-6);  // the boxes' centre (3, 4) from the scanner (0, 0)
  EXPECT_FALSE(TargetColouredLikeBackground(scene));
  EXPECT_EQ(TargetColumn(scene), "bin");
  scene.objects[2].material.color = scene.objects[0].material.color;  // the lid like the ground
  EXPECT_TRUE(TargetColouredLikeBackground(scene));
  EXPECT_EQ(TargetColumn(scene), "bin *");
  EXPECT_EQ(MeanWhere({1, 2, 4}, {true, false, true}, true), "2 scenes, mean 2.500");
  EXPECT_EQ(MeanWhere({1, 2, 4}, {true, true, true}, false), "0 scenes");
}

}  // namespace
}  // namespace lidarshop::test_scenes
