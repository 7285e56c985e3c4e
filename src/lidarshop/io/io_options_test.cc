#include <gtest/gtest.h>

#include "lidarshop/image/colormap.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/render.h"
#include "lidarshop/io/render_view.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(IoOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<PointViewOptions>();
  ExpectExactRoundTrip<PtxReadOptions>();
  ExpectExactRoundTrip<E57WriteOptions>();
}

TEST(IoOptionsInfo, Errors) {
  ExpectRejected<PointViewOptions>({{"width_px", 8}}, "width_px", "out of range [16, 16384]");
  ExpectRejected<E57WriteOptions>({{"coordinate_scale_m", -1}}, "coordinate_scale_m", "out of range >= 0");
  EXPECT_EQ(ParseEnum<RenderChannel>("normals"), RenderChannel::kNormals);
  EXPECT_EQ(ToString(ColorMap::kMagma), "magma");
  EXPECT_THROW(ParseEnum<RenderChannel>("depth"), OptionsError);
}

}  // namespace lidarshop
