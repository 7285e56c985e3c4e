#include <gtest/gtest.h>

#include "lidarshop/util/options_test_util.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {

TEST(VerifyOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<ModelOptions>();
  ExpectExactRoundTrip<VerifyOptions>();
  ExpectExactRoundTrip<SweepOptions>();
}

TEST(VerifyOptionsInfo, Errors) {
  ExpectRejected<VerifyOptions>({{"sigma_m", 0}}, "sigma_m", "out of range (0, 1000]");
  ExpectRejected<VerifyOptions>({{"allowance", 0.1}}, "allowance", "did you mean 'allowance_m'");
  ExpectRejected<ModelOptions>({{"point_source", "vertex"}}, "point_source", "did you mean 'vertices'");
  ExpectRejected<SweepOptions>({{"x_min_m", 5}, {"x_max_m", 1}}, "x_max_m", "below x_min_m");
  ExpectRejected<SweepOptions>({{"step_m", 0.001}, {"max_poses", 1000}}, "max_poses", "poses exceed it");
}

TEST(VerifyOptionsInfo, ResultWithNothingComparableIsNull) {
  const auto json = ToJson(VerifyResult{});
  EXPECT_TRUE(json["consistency"].is_null());
  EXPECT_FALSE(json["has_comparable_pairs"].get<bool>());
}

}  // namespace lidarshop
