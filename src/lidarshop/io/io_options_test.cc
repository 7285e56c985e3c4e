#include <gtest/gtest.h>

#include "lidarshop/image/colormap.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/render.h"
#include "lidarshop/io/render_layout.h"
#include "lidarshop/io/render_view.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(IoOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<PointViewOptions>();
  ExpectExactRoundTrip<PictureLayoutOptions>();
  ExpectExactRoundTrip<PtxReadOptions>();
  ExpectExactRoundTrip<E57WriteOptions>();
  ExpectExactRoundTrip<LasWriteOptions>();
}

TEST(IoOptionsInfo, Errors) {
  ExpectRejected<PointViewOptions>({{"width_px", 8}}, "width_px", "out of range [16, 16384]");
  ExpectRejected<PictureLayoutOptions>({{"width_px", -1}}, "width_px", "out of range [0, 16384]");
  EXPECT_EQ(ParseEnum<PictureView>("top"), PictureView::kTop);
  EXPECT_THROW(ParseEnum<PixelAspect>("wide"), OptionsError);
  ExpectRejected<E57WriteOptions>({{"coordinate_scale_m", -1}}, "coordinate_scale_m", "out of range >= 0");
  ExpectRejected<LasWriteOptions>({{"point_format", 9}}, "point_format", "out of range [-1, 8]");
  EXPECT_THROW(Validate(LasWriteOptions{.minor_version = 2, .point_format = 7}), OptionsError);
  EXPECT_EQ(ParseEnum<RenderChannel>("normals"), RenderChannel::kNormals);
  EXPECT_EQ(ToString(ColorMap::kMagma), "magma");
  EXPECT_THROW(ParseEnum<RenderChannel>("depth"), OptionsError);
}

}  // namespace lidarshop
