// Colour maps and legends for showing scan channels as pictures (RGB, 8-bit).
//
// Metric channels (range, depth, intensity) use perceptual maps: viridis and magma are perceptually uniform
// with monotone lightness (van der Walt & Smith, matplotlib 2015); turbo (Mikhailov, Google 2019) is a
// rainbow with smooth lightness for more contrast. The tables come from OpenCV's colormap module, sampled at
// 256 levels. Labels get distinct colours from a golden-ratio walk around the hue circle.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class ColorMap { kViridis, kTurbo, kMagma, kGray };
template <>
const EnumInfo& EnumInfoOf<ColorMap>();

// Names (util/enum_names.h): "viridis", "turbo", "magma", "gray".

// The 256 RGB colours of `map`, low to high.
const std::vector<cv::Vec3b>& ColorMapTable(ColorMap map);

// The values between `min_value` (first colour) and `max_value` (last colour),
// in `unit` (shown on the legend).
struct ColorScale {
  double min_value = 0.0;
  double max_value = 1.0;
  ColorMap map = ColorMap::kViridis;
  std::string unit;  // e.g. "m"
};

// A scale from the `low_fraction` and `high_fraction` quantiles of the finite values of `values`
// (CV_32F) where `mask` (CV_8U, empty = everywhere) is non-zero; robust to a few stray far
// points. {0, 1} when nothing is valid.
ColorScale AutoScale(const cv::Mat& values, const cv::Mat& mask, ColorMap map, const std::string& unit,
                     double low_fraction = 0.01, double high_fraction = 0.99);

// Maps a CV_32F image through `scale` to CV_8UC3 RGB; values outside the scale are clamped; cells where
// `mask` is zero or the value is not finite get `invalid_color`.
cv::Mat ApplyColorMap(const cv::Mat& values, const cv::Mat& mask, const ColorScale& scale,
                      const cv::Vec3b& invalid_color = cv::Vec3b(0, 0, 0));

// A vertical colour bar, highest value at the top, with tick values and the unit, on a white background
// (CV_8UC3 RGB, `height` rows, about 100 columns).
cv::Mat ColorScaleBar(const ColorScale& scale, int height);

// The colour of an object label: distinct, stable, never black; `negative_color` for labels < 0 (no label).
cv::Vec3b LabelColor(int32_t label, const cv::Vec3b& negative_color = cv::Vec3b(0, 0, 0));

// Colours a CV_32S label image; cells where `mask` (CV_8U, empty = everywhere) is zero get black.
cv::Mat ColorLabels(const cv::Mat& labels, const cv::Mat& mask);

// A legend of label swatches with their numbers (CV_8UC3 RGB, `height` rows at least), and the object's name
// where `names` has one ("3  hatchback"); the legend widens to fit the longest line.
cv::Mat LabelLegend(const std::vector<int32_t>& labels, int height,
                    const std::map<int32_t, std::string>& names = {});

// Cells without a return (or, in projections, pixels no point falls on) are drawn as a quiet grey checker, the
// way image editors show transparency: light and mid grey squares of kNoReturnCheckerPx pixels. Its greys can
// be colours of the gray map; the checker pattern (two greys alternating every 8 pixels in both directions),
// not the colour, tells "nothing here" from a value, and it stays out of the way of the data around it.
inline const cv::Vec3b kNoReturnColorA(204, 204, 204);
inline const cv::Vec3b kNoReturnColorB(160, 160, 160);
constexpr int kNoReturnCheckerPx = 8;
inline cv::Vec3b NoReturnColor(int row, int col) {
  return ((row / kNoReturnCheckerPx + col / kNoReturnCheckerPx) % 2 == 0) ? kNoReturnColorA : kNoReturnColorB;
}
// Paints the no-return checker on `image` (CV_8UC3) where `valid` (CV_8U, same size) is zero.
void PaintNoReturn(cv::Mat* image, const cv::Mat& valid);
// A small key for the checker: a swatch and `text` (CV_8UC3, `width` columns, white ground).
cv::Mat NoReturnKey(int width, const std::string& text = "no return");

// ASPRS standard point classes (LAS 1.4 R15, table 17): the name of a class code ("ground" for 2, "building"
// for 6, ...; "class 23" for codes without a standard name) and its usual colour, as CloudCompare, QGIS and
// PDAL's viewers show them (2 ground brown, 3-5 vegetation light to dark green, 6 building orange-red, 9 water
// blue, 7 and 18 noise magenta, 1 unclassified light grey, ...).
std::string AsprsClassName(int32_t code);
cv::Vec3b AsprsClassColor(int32_t code);
// Colours a CV_32S image of ASPRS class codes; cells where `mask` (CV_8U, empty = everywhere) is zero get black.
cv::Mat ColorAsprsClasses(const cv::Mat& classes, const cv::Mat& mask);

// A legend of colour swatches, one line of text each (CV_8UC3 RGB, `height` rows at least, white ground); it
// widens to fit the longest line.
cv::Mat SwatchLegend(const std::vector<std::pair<cv::Vec3b, std::string>>& entries, int height);

// `top` above `bottom` (CV_8UC3), padded with white to the wider width.
cv::Mat StackLegends(const cv::Mat& top, const cv::Mat& bottom);

// `image` (CV_8UC3) with `legend` to its right, both padded with white to the taller height.
cv::Mat BesideLegend(const cv::Mat& image, const cv::Mat& legend);

}  // namespace lidarshop
