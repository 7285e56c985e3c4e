#include <gtest/gtest.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(IoOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<PtxReadOptions>();
  ExpectExactRoundTrip<E57WriteOptions>();
  ExpectExactRoundTrip<LasWriteOptions>();
}

TEST(IoOptionsInfo, Errors) {
  ExpectRejected<E57WriteOptions>({{"coordinate_scale_m", -1}}, "coordinate_scale_m", "out of range >= 0");
  ExpectRejected<LasWriteOptions>({{"point_format", 9}}, "point_format", "out of range [-1, 8]");
  EXPECT_THROW(Validate(LasWriteOptions{.minor_version = 2, .point_format = 7}), OptionsError);
}

}  // namespace lidarshop
