#include <gtest/gtest.h>

#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(RecolorOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<ResectionOptions>();
  ExpectExactRoundTrip<RecolorOptions>();
}

TEST(RecolorOptionsInfo, Errors) {
  ExpectRejected<ResectionOptions>({{"radial_coefficients", 4}}, "radial_coefficients",
                                   "out of range [0, 3]");
  ExpectRejected<RecolorOptions>({{"visibility", "z-buffer"}}, "visibility", "did you mean 'zbuffer'");
  ExpectRejected<RecolorOptions>({{"zbuffer_scale", 0}}, "zbuffer_scale", "out of range (0, 1]");
  ExpectRejected<RecolorOptions>({{"skirt_depth_m", -0.1}}, "skirt_depth_m", "out of range");
  EXPECT_EQ(ToString(PairKind::kPixelPixel), "pixel-pixel");
  ResectionOptions no_photo;
  EXPECT_THROW(no_photo.Check(), OptionsError);  // the photo size is needed to resect
}

}  // namespace lidarshop
