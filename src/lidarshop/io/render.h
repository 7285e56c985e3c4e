// Pictures of a scan's channels in image orientation (row 0 = top = highest elevation, column = scan column),
// RGB 8-bit, ready for WriteImage. RenderScan draws one pixel per ray (the editor's picture); RenderPicture
// first lays the scan out (render_layout.h: square angular pixels, spherical or orthographic projections of
// unorganized clouds) and is what `lidarshop render` writes.
//
//   range      metres from the scanner, perceptual colour map (viridis by default) over the 1-99 % quantiles
//   intensity  return strength, grey (or any map) over the 1-99 % quantiles; a scan without intensity throws
//              InputError "NAME has no intensity channel; it has: xyz, rgb"
//   rgb        the scan's colour (InputError when the scan has none)
//   normals    the normal channel (synthetic scans), or normals estimated from the neighbouring points,
//              shown as (n + 1) / 2 in the scanner frame: red = x (right), green = y (forward), blue = z (up)
//   labels     distinct colours per object label (InputError when the scan has none)
//   valid      white where the ray returned, black elsewhere
// `min_value` / `max_value` replace either quantile. Cells without a return are a magenta / pink checker
// (colormap.h: no colour map, label or normal colour takes those colours), except in `valid`. With `legend`,
// a colour scale bar (range, intensity), label swatches with the objects' names (labels) or the normals key
// (normals) is placed to the right, with a "no return" swatch under it when the picture has such cells.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/image/colormap.h"
#include "lidarshop/io/render_layout.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class RenderChannel { kRange, kRgb, kIntensity, kNormals, kLabels, kValid };
template <>
const EnumInfo& EnumInfoOf<RenderChannel>();

struct RenderOptions {
  RenderChannel channel = RenderChannel::kRange;
  bool legend = false;                // add a colour scale bar / label swatches to the right
  std::optional<ColorMap> color_map;  // default: viridis for range, gray for intensity
  double min_value =
      std::numeric_limits<double>::quiet_NaN();  // channel units (m, intensity); NaN = automatic
  double max_value = std::numeric_limits<double>::quiet_NaN();
  // Legend text of object labels ("3  hatchback"), e.g. a scene's object names; labels without one show
  // their number.
  std::map<int32_t, std::string> label_names;

  void Check() const;  // throws OptionsError (min >= max)
};

struct RenderResult {
  cv::Mat image;                    // CV_8UC3 RGB, rows x (cols + legend width)
  std::optional<ColorScale> scale;  // for metric channels: the values the colours stand for
};

// One pixel per ray (rows x cols, plus the legend).
RenderResult RenderScan(const Scan& scan, const RenderOptions& options);

struct PictureResult {
  cv::Mat image;                    // CV_8UC3 RGB, layout.picture_size (plus the legend to the right)
  std::optional<ColorScale> scale;  // for metric channels: the values the colours stand for
  PictureLayout layout;             // what was drawn where (render_layout.h)
};

// The scan laid out by `layout_options` (square angular pixels by default; a spherical grid for unorganized
// clouds), coloured like RenderScan.
PictureResult RenderPicture(const Scan& scan, const RenderOptions& options,
                            const PictureLayoutOptions& layout_options);

// The values of a channel for float pictures (EXR, TIFF): range in metres or intensity (CV_32F), normals
// (CV_32FC3, scanner frame); NaN where the ray did not return. Throws OptionsError for the other channels
// (8-bit pictures) and InputError when the scan lacks the channel.
cv::Mat ChannelValues(const Scan& scan, RenderChannel channel);

// True for the channels ChannelValues gives: range, intensity, normals.
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
