// Pictures of a scan's channels in image orientation (row 0 = top = highest elevation, column = scan column),
// RGB 8-bit, ready for WriteImage. RenderScan draws one pixel per ray (the editor's picture); RenderPicture
// first lays the scan out (render_layout.h: square angular pixels, spherical or orthographic projections of
// unorganized clouds) and is what `lidarshop render` writes.
//
//   range          metres from the scanner, perceptual colour map (viridis by default) over the 1-99 % quantiles
//   elevation      world z in metres (the file's own z: a LAS file's elevations), viridis over the 1-99 %
//                  quantiles; the default of the orthographic views on the command line
//   intensity      return strength in the file's units (IntensityFileRange: a LAS file's 16-bit values 0-65535,
//                  an E57's between its intensity limits, a PTX's 0-1), grey (or any map) over the 1-99 % quantiles; a scan without intensity throws
//                  InputError "NAME has no intensity channel; it has: xyz, rgb"
//   rgb            the scan's colour (InputError when the scan has none)
//   normals        the normal channel (synthetic scans), or normals estimated from the neighbouring points,
//                  shown as (n + 1) / 2 in the scanner frame: red = x (right), green = y (forward), blue = z (up);
//                  orthographic views of a cloud without normals: the slope of the surface seen (as --hillshade)
//   labels         distinct colours per object label (InputError when the scan has none); the label channel of
//                  a scan read from LAS holds its classification and is drawn as `classification`
//   classification the label channel read as ASPRS classes: their usual colours and names (colormap.h:
//                  2 ground brown, 5 high vegetation green, 6 building orange-red, 9 water blue, ...)
//   valid          white where the ray returned, black elsewhere
// `min_value` / `max_value` replace either quantile (in the channel's units). Cells without a return, and
// pixels of a projection that no point covers, are a quiet grey checker (colormap.h), except in `valid`. With
// `legend`, a colour scale bar (range, elevation, intensity), swatches with the objects' or classes' names
// (labels, classification) or the normals key (normals) is placed to the right, with a "no return" (scan
// grids) or "no point" (projections) swatch under it when the picture has such pixels. `hillshade` (top,
// front and side views) shades the colours by the gradient of the points' height towards the viewer, lit from
// the north-west (azimuth 315°, 45° up), as GDAL's and CloudCompare's hillshades are.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/image/colormap.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class RenderChannel { kRange, kRgb, kIntensity, kNormals, kLabels, kValid, kElevation, kClassification };
template <>
const EnumInfo& EnumInfoOf<RenderChannel>();

struct RenderOptions {
  RenderChannel channel = RenderChannel::kRange;
  bool legend = false;                // add a colour scale bar / label swatches to the right
  std::optional<ColorMap> color_map;  // default: viridis for range and elevation, gray for intensity
  double min_value =
      std::numeric_limits<double>::quiet_NaN();  // channel units (m, the file's intensity); NaN = automatic
  double max_value = std::numeric_limits<double>::quiet_NaN();
  // Legend text of object labels ("3  hatchback"), e.g. a scene's object names; labels without one show
  // their number.
  std::map<int32_t, std::string> label_names;
  // Orthographic views: shade the colours by the gradient of the height towards the viewer (a hillshade).
  bool hillshade = false;

  void Check() const;  // throws OptionsError (min >= max)
};

struct RenderResult {
  cv::Mat image;                    // CV_8UC3 RGB, rows x (cols + legend width)
  std::optional<ColorScale> scale;  // for metric channels: the values the colours stand for
  // The swatch legend's lines, top to bottom (labels, classification: "2  ground"), also without `legend`.
  std::vector<std::string> legend_lines;
};

// One pixel per ray (rows x cols, plus the legend).
RenderResult RenderScan(const Scan& scan, const RenderOptions& options);

struct PictureResult {
  cv::Mat image;                          // CV_8UC3 RGB, layout.picture_size (plus the legend to the right)
  std::optional<ColorScale> scale;        // for metric channels: the values the colours stand for
  std::vector<std::string> legend_lines;  // as RenderResult's
  PictureLayout layout;                   // what was drawn where (render_layout.h)
};

// The scan laid out by `layout_options` (square angular pixels by default; a spherical grid for unorganized
// clouds), coloured like RenderScan. Throws OptionsError for `hillshade` with a view that is not orthographic.
PictureResult RenderPicture(const Scan& scan, const RenderOptions& options,
                            const PictureLayoutOptions& layout_options);

// The values a picture's colours stand for, as `render --json` writes them (a ColorScale without its map).
struct ColorScaleSummary {
  double min = 0.0;  // the value of the scale's first colour, in `unit`
  double max = 0.0;  // the value of its last colour
  std::string unit;  // "m", or the intensity's unit in the file
};
template <>
const StructInfo& InfoOf<ColorScaleSummary>();

// What `render` drew on the scan's grid or an orthographic view (its --json, after the options; the other
// viewpoints write PointViewResult).
struct PictureSummary {
  std::string output;                      // the picture written
  std::string channel;                     // the channel drawn
  int width_px = 0, height_px = 0;         // its size, pixels
  std::string values;                      // float pictures: what a pixel holds; "" for 8-bit pictures
  std::optional<ColorScaleSummary> scale;  // 8-bit pictures of metric channels: the colours' values
  std::vector<std::string> legend;         // the swatch legend's lines (labels, classes)
  PictureLayoutSummary layout;             // what the picture shows
  std::string layout_file;                 // the layout written beside the picture (picture_mapping.h)
};
template <>
const StructInfo& InfoOf<PictureSummary>();

// The values in the file's units that Scan::intensity 0 and 1 stand for: intensity i was the file's
// first + i * (second - first). Readers that scale intensities to [0, 1] say from what in
// source_metadata["intensity.file_minimum"] (0 when absent) and ["intensity.file_maximum"]: LAS 0-65535, PCD
// integer fields 0 to their type's maximum, E57 its intensity limits. {0, 1} for the others (PTX, float fields).
std::pair<double, double> IntensityFileRange(const Scan& scan);

// True when the scan's label channel holds ASPRS classes: it was read from LAS (source_metadata "las.*").
bool HoldsAsprsClasses(const Scan& scan);

// The values of a channel for float pictures (EXR, TIFF): range or elevation (world z) in metres or intensity
// (0-1; CV_32F), normals (CV_32FC3, scanner frame); NaN where the ray did not return. Throws OptionsError for the other channels
// (8-bit pictures) and InputError when the scan lacks the channel.
cv::Mat ChannelValues(const Scan& scan, RenderChannel channel);

// True for the channels ChannelValues gives: range, elevation, intensity, normals.
bool HasFloatValues(RenderChannel channel);

struct ValuesResult {
  cv::Mat values;  // ChannelValues of the laid-out cells, resampled to layout.picture_size
  PictureLayout layout;
};
ValuesResult RenderValues(const Scan& scan, RenderChannel channel,
                          const PictureLayoutOptions& layout_options);

// The key of the normals picture: a hemisphere of normals facing the viewer (the scanner looks along +y),
// each pixel in the colour its normal gets, with the axes named (CV_8UC3, about `height` rows, white ground).
cv::Mat NormalsKey(int height);

// Unit normals from the neighbouring points of the grid (cross product of the horizontal and vertical central
// differences, turned towards the scanner); zero where a neighbour is missing. CV_32FC3, scanner frame.
cv::Mat EstimateGridNormals(const Scan& scan);

}  // namespace lidarshop
