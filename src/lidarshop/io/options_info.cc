// Descriptions of the file and picture options (util/options.h). RenderOptions is not described: its colour
// map is optional and its bounds are NaN for "from the data" (the render command binds them by hand).
#include <fmt/format.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/render.h"
#include "lidarshop/io/render_layout.h"
#include "lidarshop/io/render_view.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<RenderChannel>() {
  static const EnumInfo info = MakeEnumInfo<RenderChannel>(
      "channel", {{RenderChannel::kRange, "range", "metres from the scanner"},
                  {RenderChannel::kRgb, "rgb", "the scan's colour"},
                  {RenderChannel::kIntensity, "intensity", "return strength in the file's units"},
                  {RenderChannel::kNormals, "normals", "normals as (n + 1) / 2"},
                  {RenderChannel::kLabels, "labels", "object labels (a LAS file's: its classes)"},
                  {RenderChannel::kValid, "valid", "white where the ray returned"},
                  {RenderChannel::kElevation, "elevation", "world z in metres (the file's z)"},
                  {RenderChannel::kClassification, "classification",
                   "labels as ASPRS classes: their names and usual colours"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PictureView>() {
  static const EnumInfo info = MakeEnumInfo<PictureView>(
      "view", {{PictureView::kAuto, "auto", "the ray grid of organized scans, a spherical grid for clouds"},
               {PictureView::kGrid, "grid", "the scan's own ray grid"},
               {PictureView::kSphere, "sphere", "points projected onto a spherical grid around the scanner"},
               {PictureView::kTop, "top", "orthographic from above (world x right, y up)"},
               {PictureView::kFront, "front", "orthographic from the front (world x right, z up)"},
               {PictureView::kSide, "side", "orthographic from the right-hand side (world y right, z up)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PixelAspect>() {
  static const EnumInfo info = MakeEnumInfo<PixelAspect>(
      "aspect", {{PixelAspect::kSquare, "square", "square angular pixels (the finer native step)"},
                 {PixelAspect::kNative, "native", "one pixel per ray"}});
  return info;
}

template <>
const StructInfo& InfoOf<PictureLayoutOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PictureLayoutOptions> b("PictureLayoutOptions",
                                          "where the pixels of a scan picture come from");
    b.Field(&PictureLayoutOptions::view, "view", "grid, spherical or orthographic layout");
    b.Field(&PictureLayoutOptions::aspect, "aspect", "grid view: square angular pixels or one pixel per ray");
    b.Field(&PictureLayoutOptions::width_px, "width_px",
            "picture width; 0 = automatic (with only one size given the other keeps the aspect)")
        .Unit("px")
        .Range(0, 16384);
    b.Field(&PictureLayoutOptions::height_px, "height_px", "picture height; 0 = automatic")
        .Unit("px")
        .Range(0, 16384);
    b.Field(&PictureLayoutOptions::max_side_px, "max_side_px", "automatic sizes: the longer side at most")
        .Unit("px")
        .Range(16, 16384);
    b.Field(&PictureLayoutOptions::min_long_side_px, "min_long_side_px",
            "orthographic views, automatic sizes: the longer side at least (at most max_side_px)")
        .Unit("px")
        .Range(16, 16384);
    b.Field(
         &PictureLayoutOptions::point_size_px, "point_size_px",
         "side of the square drawn for each point (orthographic views and the second viewpoint); 0 = twice "
         "the local point spacing (second viewpoint: 2)")
        .Unit("px")
        .Range(0, 32);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PointViewOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PointViewOptions> b(
        "PointViewOptions", "points from a second viewpoint (eye, target, up: C++ and the camera file)");
    b.Field(&PointViewOptions::field_of_view_deg, "field_of_view_deg", "horizontal field of view")
        .Unit("deg")
        .AboveZero()
        .Below(170);
    b.Field(&PointViewOptions::width_px, "width_px", "picture width").Unit("px").Range(16, 16384);
    b.Field(&PointViewOptions::height_px, "height_px", "picture height").Unit("px").Range(16, 16384);
    b.Field(&PointViewOptions::point_size_px, "point_size_px", "side of each drawn point")
        .Unit("px")
        .Range(1, 32);
    b.Field(&PointViewOptions::synthesized_tint, "synthesized_tint", "share of magenta on synthesized points")
        .Range(0, 1);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PtxReadOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PtxReadOptions> b("PtxReadOptions", "reading PTX");
    b.Field(&PtxReadOptions::fit_grid, "fit_grid", "fit the angular grid so every cell gets a direction");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57WriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<E57WriteOptions> b("E57WriteOptions", "writing E57");
    b.Field(&E57WriteOptions::coordinate_scale_m, "coordinate_scale_m",
            "0 = float coordinates; > 0 = scaled integers with this step")
        .Unit("m")
        .Min(0);
    b.Field(&E57WriteOptions::write_no_return_directions, "write_no_return_directions",
            "keep the directions of cells without a return (in lidarshop's E57 extension; never as points)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasWriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<LasWriteOptions> b("LasWriteOptions", "writing LAS");
    b.Field(&LasWriteOptions::minor_version, "minor_version",
            "LAS 1.x: 4 (LAS 1.4) or 2 (LAS 1.2, formats 0-3)")
        .Range(2, 4);
    b.Field(&LasWriteOptions::point_format, "point_format",
            "point data record format 0-3 or 6-8; -1 = the source LAS's when it holds the attributes, else "
            "8 with NIR, 7 with colour, 6 (1.4); 3/2 with colour, 1/0 (1.2; GPS time decides)")
        .Range(-1, 8);
    b.Field(&LasWriteOptions::coordinate_scale_m, "coordinate_scale_m", "step of the stored coordinates")
        .Unit("m")
        .AboveZero()
        .Max(1);
    b.Field(&LasWriteOptions::keep_source_scale, "keep_source_scale",
            "keep the source LAS files' scale and offset when all scans share them (same integers back)");
    b.Check([](const LasWriteOptions& o) {
      CheckOption(
          o.minor_version == 2 || o.minor_version == 4,
          fmt::format("minor_version: {} is not written; 4 (LAS 1.4) or 2 (LAS 1.2)", o.minor_version));
      CheckOption(o.point_format != 4 && o.point_format != 5,
                  fmt::format("point_format: {} (waveform) is not written; 0-3 or 6-8", o.point_format));
      CheckOption(o.point_format < 6 || o.minor_version == 4,
                  fmt::format("point_format: {} needs LAS 1.4 (minor_version 4)", o.point_format));
    });
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
