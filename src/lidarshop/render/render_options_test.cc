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

// The layout's JSON keys in the order `lidarshop render --json` has always written them: the points of
// projections only, the point size of orthographic views only.
TEST(RenderOptionsInfo, LayoutSummary) {
  ExpectExactRoundTrip<PictureLayoutSummary>();
  EXPECT_EQ(InfoOf<PictureLayoutSummary>().Keys(),
            (std::vector<std::string>{"view", "description", "pixel_width", "pixel_height", "pixel_unit",
                                      "source_rows", "source_cols", "points", "points_kept", "point_size_px",
                                      "point_size"}));
  PictureLayout grid;
  grid.pixel_width = grid.pixel_height = 0.5;
  grid.pixel_unit = "deg";
  grid.cells.rows = 4;
  grid.cells.cols = 6;
  const nlohmann::ordered_json grid_json = ToJson(SummarizeLayout(grid));
  EXPECT_EQ(grid_json["view"], "grid");
  EXPECT_EQ(grid_json["source_cols"], 6);
  EXPECT_FALSE(grid_json.contains("points"));
  EXPECT_FALSE(grid_json.contains("point_size_px"));
  PictureLayout top = grid;
  top.view = PictureView::kTop;
  top.pixel_unit = "m";
  top.points = 100;
  top.points_kept = 80;
  top.splat_px = 3;
  const nlohmann::ordered_json top_json = ToJson(SummarizeLayout(top));
  EXPECT_EQ(top_json["points_kept"], 80);
  EXPECT_EQ(top_json["point_size_px"].dump(), "3.0");
  EXPECT_EQ(top_json["point_size"], "--point-size");
  EXPECT_EQ(top_json.size(), 11u);
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
