// Descriptions of the picture options (util/options.h). RenderOptions is not described: its colour map is
// optional and its bounds are NaN for "from the data" (the render command binds them by hand).
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/render_view.h"
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
const StructInfo& InfoOf<PointViewCamera>() {
  static const StructInfo info = [] {
    StructBuilder<PointViewCamera> b("PointViewCamera",
                                     "a second viewpoint's camera (the camera file; world frame)");
    b.Field(&PointViewCamera::eye, "eye", "camera centre x, y, z").Unit("m");
    b.Field(&PointViewCamera::target, "target", "the point looked at x, y, z").Unit("m");
    b.Field(&PointViewCamera::up, "up", "the picture's up x, y, z (any length)");
    b.Field(&PointViewCamera::fov_deg, "fov_deg", "horizontal field of view").Unit("deg");
    b.Field(&PointViewCamera::width, "width", "picture width").Unit("px");
    b.Field(&PointViewCamera::height, "height", "picture height").Unit("px");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ViewGround>() {
  static const StructInfo info = [] {
    StructBuilder<ViewGround> b("ViewGround", "the ground whose normal a second viewpoint took as up");
    b.Field(&ViewGround::share, "share", "share of the returns used that lie on the ground, (0, 1]");
    b.Field(&ViewGround::tilt_deg, "tilt_deg", "angle between its normal and the scan's up").Unit("deg");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PointViewResult>() {
  static const StructInfo info = [] {
    StructBuilder<PointViewResult> b("PointViewResult",
                                     "what render --eye, --orbit or --camera drew (render --json)");
    b.Field(&PointViewResult::up_from, "up_from",
            "--orbit: ground (the ground's normal is up) or scan (the scan's up)");
    b.Field(&PointViewResult::ground, "ground", "--orbit with a ground: the plane whose normal is up");
    b.Field(&PointViewResult::output, "output", "the picture written");
    b.Field(&PointViewResult::width_px, "width_px", "picture width").Unit("px");
    b.Field(&PointViewResult::height_px, "height_px", "picture height").Unit("px");
    b.Field(&PointViewResult::eye_in_world, "eye_in_world", "camera centre x, y, z (= camera.eye)").Unit("m");
    b.Field(&PointViewResult::target_in_world, "target_in_world", "the point looked at (= camera.target)")
        .Unit("m");
    b.Field(&PointViewResult::up_in_world, "up_in_world", "the picture's up (= camera.up)");
    b.Field(&PointViewResult::camera, "camera", "the camera drawn with, as --write-camera writes it");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ColorScaleSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ColorScaleSummary> b("ColorScaleSummary", "the values a picture's colours stand for");
    b.Field(&ColorScaleSummary::min, "min", "the value of the scale's first colour (unit)");
    b.Field(&ColorScaleSummary::max, "max", "the value of its last colour (unit)");
    b.Field(&ColorScaleSummary::unit, "unit", "m, or the intensity's unit in the file");
    return b.Build();
  }();
  return info;
}

// In the order `lidarshop render --json` has always written it.
template <>
const StructInfo& InfoOf<PictureSummary>() {
  static const StructInfo info = [] {
    StructBuilder<PictureSummary> b(
        "PictureSummary", "what render drew on the scan's grid or an orthographic view (render --json)");
    b.Field(&PictureSummary::output, "output", "the picture written");
    b.Field(&PictureSummary::channel, "channel", "the channel drawn");
    b.Field(&PictureSummary::width_px, "width_px", "picture width").Unit("px");
    b.Field(&PictureSummary::height_px, "height_px", "picture height").Unit("px");
    b.Field(&PictureSummary::values, "values", "float pictures (EXR, TIFF): what a pixel holds")
        .OmitWhenEmpty();
    b.Field(&PictureSummary::scale, "scale", "8-bit pictures of metric channels: the values of the colours");
    b.Field(&PictureSummary::legend, "legend", "the swatch legend's lines, top to bottom (labels, classes)")
        .OmitWhenEmpty();
    b.Field(&PictureSummary::layout, "layout", "what the picture shows");
    b.Field(&PictureSummary::layout_file, "layout_file",
            "the layout written beside the picture: where strokes and masks painted on it fall on the scan");
    return b.Build();
  }();
  return info;
}

// In the order `lidarshop render --json` has always written its "layout".
template <>
const StructInfo& InfoOf<PictureLayoutSummary>() {
  static const StructInfo info = [] {
    StructBuilder<PictureLayoutSummary> b("PictureLayoutSummary", "what a picture of a scan shows");
    b.Field(&PictureLayoutSummary::view, "view", "the view drawn");
    b.Field(&PictureLayoutSummary::description, "description", "one line saying what was done");
    b.Field(&PictureLayoutSummary::pixel_width, "pixel_width", "size of a pixel across (pixel_unit)");
    b.Field(&PictureLayoutSummary::pixel_height, "pixel_height", "size of a pixel down (pixel_unit)");
    b.Field(&PictureLayoutSummary::pixel_unit, "pixel_unit", "deg (grid, sphere) or m (top, front, side)");
    b.Field(&PictureLayoutSummary::source_rows, "source_rows", "rows of the grid coloured").Unit("cells");
    b.Field(&PictureLayoutSummary::source_cols, "source_cols", "columns of the grid coloured").Unit("cells");
    b.Field(&PictureLayoutSummary::points, "points", "projections: points projected");
    b.Field(&PictureLayoutSummary::points_kept, "points_kept",
            "projections: points kept (the nearest of each cell, or shown on a pixel)");
    b.Field(&PictureLayoutSummary::point_size_px, "point_size_px",
            "orthographic views: the median side of the squares drawn")
        .Unit("px");
    b.Field(&PictureLayoutSummary::point_size, "point_size", "orthographic views: where that size came from");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
