// Pictures of a scan's channels: one pixel per ray, in image orientation (row 0 = top = highest elevation,
// column = scan column), RGB 8-bit, ready for WriteImage.
//
//   range      metres from the scanner, perceptual colour map (viridis by default) over the 1-99 % quantiles
//   intensity  return strength, grey (or any map) over [0, 1] unless min/max are given; a scan without
//              intensity throws InputError "NAME has no intensity channel; it has: xyz, rgb"
//   rgb        the scan's colour (InputError when the scan has none)
//   normals    the normal channel (synthetic scans), or normals estimated from the neighbouring points,
//              shown as (n + 1) / 2 in the scanner frame
//   labels     distinct colours per object label (InputError when the scan has none)
//   valid      white where the ray returned, black elsewhere
// Cells without a return are black in every channel. With `legend`, a colour scale bar (metric channels) or a
// list of label swatches (labels) is placed to the right.
#pragma once

#include <limits>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/image/colormap.h"
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

  void Check() const;  // throws OptionsError (min >= max)
};

struct RenderResult {
  cv::Mat image;                    // CV_8UC3 RGB, rows x (cols + legend width)
  std::optional<ColorScale> scale;  // for metric channels: the values the colours stand for
};

RenderResult RenderScan(const Scan& scan, const RenderOptions& options);

// Unit normals from the neighbouring points of the grid (cross product of the horizontal and vertical central
// differences, turned towards the scanner); zero where a neighbour is missing. CV_32FC3, scanner frame.
cv::Mat EstimateGridNormals(const Scan& scan);

}  // namespace lidarshop
