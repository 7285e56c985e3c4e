#include <gtest/gtest.h>

#include "lidarshop/image/colormap.h"
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/render_view.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(RenderOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<PointViewOptions>();
  ExpectExactRoundTrip<PictureLayoutOptions>();
}

TEST(RenderOptionsInfo, Errors) {
  ExpectRejected<PointViewOptions>({{"width_px", 8}}, "width_px", "out of range [16, 16384]");
  ExpectRejected<PictureLayoutOptions>({{"width_px", -1}}, "width_px", "out of range [0, 16384]");
  EXPECT_EQ(ParseEnum<PictureView>("top"), PictureView::kTop);
  EXPECT_THROW(ParseEnum<PixelAspect>("wide"), OptionsError);
  EXPECT_EQ(ParseEnum<RenderChannel>("normals"), RenderChannel::kNormals);
  EXPECT_EQ(ToString(ColorMap::kMagma), "magma");
  EXPECT_THROW(ParseEnum<RenderChannel>("depth"), OptionsError);
}

}  // namespace lidarshop
