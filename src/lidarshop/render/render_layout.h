// Where the pixels of a picture of a scan come from: the scan's own ray grid, or its points projected onto a
// spherical grid around the scanner or onto an orthographic grid. The result is itself an organized scan (one
// cell per picture cell) that render.h colours like any other, plus the picture size the cells are resampled
// to (nearest neighbour, so values stay exact and no-return stays no-return).
//
//   grid    the scan's ray grid (organized scans). aspect square: resampled so that a pixel covers the same
//           angle across and down, the finer of the two native steps (pumpA: 0.250° x 0.0675° per ray
//           becomes 0.0675° square pixels, 3.7 times as many columns); aspect native: one pixel per ray
//   sphere  the points projected from the scanner position (world_from_scanner's origin) onto a grid of
//           square angular cells, azimuth increasing to the right, elevation up; the nearest point of each
//           cell is kept. Azimuths start after the widest empty sector, so a cloud behind the scanner is not
//           cut in two. Automatic size: about three points a cell over the angular bounding box
//   top     orthographic from above in the world frame: world x to the right, world y up, the highest point
//           of each pixel kept. The window holds the 0.5-99.5 % quantiles of the points on each axis widened
//           by a quarter of their span (at most the points' extent), so that a scan's few far stray points do
//           not shrink the rest to a corner. Automatic size: one point a pixel over the window, at least
//           min_long_side_px (1000) and at most max_side_px on the longer side, square pixels
//   front   orthographic from the front in the world frame: world x to the right, world z up, looking along
//           world +y, the point with the smallest y of each pixel kept
//   side    orthographic from the right-hand side in the world frame: world y to the right, world z up,
//           looking along world -x, the point with the largest x of each pixel kept
//   Orthographic views draw every point as a square with a depth test (the point nearest to the viewer wins
//   each pixel: a tree's crown hides the ground under it). point_size_px > 0 gives every square that side;
//   0 (automatic) makes each square twice the local point spacing (the side of a window around the point
//   holding at least 8 pixels with a point, over the square root of their number; at most twice the median
//   square, so that isolated points stay small), so that a sparse aerial cloud gives a closed picture.
//   Pixels no square covers stay empty (the checker of colormap.h)
//   auto    grid for organized scans, sphere for unorganized clouds (IsUnorganized)
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class PictureView { kAuto, kGrid, kSphere, kTop, kFront, kSide };
template <>
const EnumInfo& EnumInfoOf<PictureView>();

enum class PixelAspect { kSquare, kNative };
template <>
const EnumInfo& EnumInfoOf<PixelAspect>();

struct PictureLayoutOptions {
  PictureView view = PictureView::kAuto;
  PixelAspect aspect = PixelAspect::kSquare;  // grid view: square angular pixels, or one pixel per ray
  // Picture size in pixels; 0 = automatic. With only one of them given the other keeps the aspect; with both
  // the picture is exactly that size (pixels need not be square then).
  int width_px = 0;
  int height_px = 0;
  int max_side_px = 4096;  // pixels: automatic sizes are scaled down to at most this on the longer side
  // Orthographic views: automatic sizes are scaled up to at least this on the longer side (pixels; at most
  // max_side_px).
  int min_long_side_px = 1000;
  // Orthographic views: side of the square drawn for each point, pixels; 0 = from the local point spacing.
  int point_size_px = 0;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<PictureLayoutOptions>();

struct PictureLayout {
  PictureView view = PictureView::kGrid;  // the view used (never kAuto)
  // The organized scan to colour: the input itself (grid) or one cell per picture pixel (projections, whose
  // cells keep the chosen point's channels: point and range in the scanner frame, intensity, colour, label,
  // normal, synthesized). Same pose, name and source_metadata as the input.
  Scan cells;
  cv::Size picture_size;  // the picture's size; the cells' images are resampled to it (nearest neighbour)
  // Size of one picture pixel across and down: degrees (grid, sphere) or metres (top, front).
  double pixel_width = 0, pixel_height = 0;
  std::string pixel_unit;  // "deg" or "m"
  // Projections: points projected, and points kept (the nearest of each cell; orthographic views: the points
  // that show on at least one pixel); grid: both 0.
  int64_t points = 0, points_kept = 0;
  // Orthographic views: the median side of the squares the points were drawn as (pixels), and whether it came
  // from the local point spacing (automatic) or point_size_px.
  double splat_px = 0;
  bool splat_automatic = false;
  // Orthographic views: for each picture pixel, the scan cell whose point it shows (row * scan cols + col;
  // CV_32S, -1 where no point shows), so strokes painted on the picture map back onto the scan
  // (picture_mapping.h). Empty for the other views.
  cv::Mat source_cells;
  // Orthographic views: the world coordinates of the picture's left edge (top, front: x; side: y) and top
  // edge (top: y; front, side: z), metres; a pixel's size is pixel_width x pixel_height.
  double left_m = 0, top_m = 0;
  std::string Describe() const;  // one line saying what was done, for stderr and --json
};

// A picture's layout in brief: the "layout" of `lidarshop render --json`, in its order. Described.
struct PictureLayoutSummary {
  PictureView view = PictureView::kGrid;
  std::string description;  // PictureLayout::Describe()
  double pixel_width = 0, pixel_height = 0;
  std::string pixel_unit;
  int source_rows = 0, source_cols = 0;  // PictureLayout::cells: the grid coloured
  // Projections (every view but the grid): points projected and kept.
  std::optional<int64_t> points, points_kept;
  // Orthographic views: the median side of the squares drawn, and where it came from (the local spacing, or
  // the size asked for: "--point-size", the flag that sets PictureLayoutOptions::point_size_px).
  std::optional<double> point_size_px;
  std::optional<std::string> point_size;
};
PictureLayoutSummary SummarizeLayout(const PictureLayout& layout);

template <>
const StructInfo& InfoOf<PictureLayoutSummary>();

// True for a cloud without a ray grid: a 1 x N (or N x 1) scan without a fitted grid, as readers make of an
// E57 without row/column indices, an unorganized PCD/PLY, LAS and XYZ.
bool IsUnorganized(const Scan& scan);

// The angular size of one ray across (azimuth) and down (elevation), radians, from the scan's grid when it has
// one, else the median step between neighbouring valid rays; 0 when it cannot be told (a single column/row).
cv::Vec2d NativeStepsRad(const Scan& scan);

// Throws OptionsError for bad options, InputError (naming the scan) when a projection has no point to show.
PictureLayout LayOutPicture(const Scan& scan, const PictureLayoutOptions& options);

// Orthographic views: the unit vector of the world frame pointing from the scene towards the viewer (top: +z,
// front: -y, side: +x); the zero vector for the other views. A point's height towards the viewer is its
// world position dotted with it (the elevation in the top view).
Eigen::Vector3d TowardViewer(PictureView view);

// Nearest-neighbour resampling to `size`, pixel centres to pixel centres (values are never mixed).
cv::Mat ResampleNearest(const cv::Mat& image, cv::Size size);

}  // namespace lidarshop
