#include <gtest/gtest.h>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(SegmentOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<SegmentOptions>();
  ExpectExactRoundTrip<CutWeights>();
}

TEST(SegmentOptionsInfo, Errors) {
  ExpectRejected<SegmentOptions>({{"object_uniform", 1.0}}, "object_uniform", "out of range (0, 1)");
  ExpectRejected<SegmentOptions>({{"method", "twostep"}}, "method", "did you mean 'two-step'");
  ExpectRejected<SegmentOptions>(
      {{"depth_step", {{"lambda_r", 0}, {"lambda_g", 0}, {"lambda_b", 0}, {"lambda_d", 0}}}},
      "depth_step.lambda_d", "at least one channel weight");
}

}  // namespace lidarshop
