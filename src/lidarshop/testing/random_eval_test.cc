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

}  // namespace
}  // namespace lidarshop::test_scenes
