#include "lidarshop/render/render_layout.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
// Automatic projection sizes: about this many points a cell over the bounding box. Points fall on cells
// unevenly (a Poisson-like spread leaves e^-3 = 5 % of a surface's cells empty at 3, 37 % at 1).
constexpr double kPointsPerCell = 3.0;
// Orthographic windows: these quantiles of the points on each axis.
constexpr double kWindowLow = 0.005, kWindowHigh = 0.995, kWindowMargin = 0.25;

double Median(std::vector<double>* values) {
  if (values->empty()) return 0.0;
  const auto middle = values->begin() + values->size() / 2;
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

// Picture size from a natural size (width, height in pixels, fractional) and the options: automatic sizes
// are capped to max_side_px; one given side keeps the aspect; two given sides are taken as they are.
cv::Size PictureSize(double natural_width, double natural_height, const PictureLayoutOptions& options) {
  natural_width = std::max(natural_width, 1.0);
  natural_height = std::max(natural_height, 1.0);
  double width = natural_width, height = natural_height;
  if (options.width_px > 0 && options.height_px > 0) {
    return cv::Size(options.width_px, options.height_px);
  } else if (options.width_px > 0) {
    width = options.width_px;
    height = natural_height * width / natural_width;
  } else if (options.height_px > 0) {
    height = options.height_px;
    width = natural_width * height / natural_height;
  } else {
    const double longer = std::max(width, height);
    if (longer > options.max_side_px) {
      width *= options.max_side_px / longer;
      height *= options.max_side_px / longer;
    }
  }
  return cv::Size(std::max(1, static_cast<int>(std::lround(width))),
                  std::max(1, static_cast<int>(std::lround(height))));
}

// A picture coordinate of every valid point (u to the right, v up), its depth (smaller = nearer, kept) and
// its cell; the projection keeps the nearest point of every picture cell.
struct ProjectedPoint {
  double u, v, depth;
  int row, col;
};

// Fills an organized cells scan of `size` from the projected points: each cell takes the channels of its
// nearest point. Returns the number of points kept.
int64_t FillCells(const Scan& scan, const std::vector<ProjectedPoint>& projected, Scan* cells) {
  cv::Mat depth(cells->rows, cells->cols, CV_64F, cv::Scalar(std::numeric_limits<double>::infinity()));
  cv::Mat source(cells->rows, cells->cols, CV_32SC2, cv::Scalar::all(-1));
  for (const ProjectedPoint& p : projected) {
    const int col = std::clamp(static_cast<int>(std::floor(p.u)), 0, cells->cols - 1);
    const int row = std::clamp(static_cast<int>(std::floor(p.v)), 0, cells->rows - 1);
    double& best = depth.at<double>(row, col);
    if (p.depth < best) {
      best = p.depth;
      source.at<cv::Vec2i>(row, col) = cv::Vec2i(p.row, p.col);
    }
  }
  int64_t kept = 0;
  for (int row = 0; row < cells->rows; ++row) {
    for (int col = 0; col < cells->cols; ++col) {
      const cv::Vec2i from = source.at<cv::Vec2i>(row, col);
      if (from[0] < 0) continue;
      ++kept;
      const int r = from[0], c = from[1];
      cells->valid.at<uint8_t>(row, col) = kValid;
      cells->range.at<float>(row, col) = scan.range.at<float>(r, c);
      cells->point.at<cv::Vec3f>(row, col) = scan.point.at<cv::Vec3f>(r, c);
      if (!scan.intensity.empty()) cells->intensity.at<float>(row, col) = scan.intensity.at<float>(r, c);
      if (scan.has_color()) cells->color.at<cv::Vec3b>(row, col) = scan.color.at<cv::Vec3b>(r, c);
      if (!scan.label.empty()) cells->label.at<int32_t>(row, col) = scan.label.at<int32_t>(r, c);
      if (!scan.normal.empty()) cells->normal.at<cv::Vec3f>(row, col) = scan.normal.at<cv::Vec3f>(r, c);
      if (!scan.synthesized.empty()) {
        cells->synthesized.at<uint8_t>(row, col) = scan.synthesized.at<uint8_t>(r, c);
      }
      // Orthographic cells have no ray grid: their direction is the point's own.
      if (cells->grid.azimuth_rad.empty()) {
        const cv::Vec3f p = cells->point.at<cv::Vec3f>(row, col);
        const float norm = static_cast<float>(cv::norm(p));
        if (norm > 0) cells->direction.at<cv::Vec3f>(row, col) = p / norm;
      }
    }
  }
  return kept;
}

Scan EmptyCells(const Scan& scan, cv::Size size) {
  Scan cells = MakeScan(size.height, size.width, scan.has_color());
  cells.world_from_scanner = scan.world_from_scanner;
  cells.name = scan.name;
  cells.source_metadata = scan.source_metadata;  // what the channels mean (LAS classes, intensity scale)
  if (scan.intensity.empty()) cells.intensity.release();
  if (!scan.label.empty()) cells.label = cv::Mat(size, CV_32S, cv::Scalar(kNoLabel));
  if (!scan.normal.empty()) cells.normal = cv::Mat(size, CV_32FC3, cv::Scalar::all(0));
  if (!scan.synthesized.empty()) cells.synthesized = cv::Mat(size, CV_8U, cv::Scalar(0));
  return cells;
}

void ThrowNothingToProject(const Scan& scan, PictureView view) {
  ThrowInputError(scan.name, "", "",
                  fmt::format("no point with a return to project for the {} view", ToString(view)));
}

PictureLayout LayOutSphere(const Scan& scan, const PictureLayoutOptions& options) {
  struct Angles {
    double azimuth, elevation;
    int row, col;
  };
  std::vector<Angles> angles;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col) || scan.range.at<float>(row, col) <= 0) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(row, col);
      angles.push_back({std::atan2(p[0], p[1]), std::atan2(p[2], std::hypot(p[0], p[1])), row, col});
    }
  }
  if (angles.empty()) ThrowNothingToProject(scan, PictureView::kSphere);
  // The azimuth window starts after the widest empty sector (the wrap-around sector included).
  std::vector<double> azimuths;
  azimuths.reserve(angles.size());
  for (const Angles& a : angles) azimuths.push_back(a.azimuth);
  std::sort(azimuths.begin(), azimuths.end());
  double widest_gap = azimuths.front() + 2 * M_PI - azimuths.back(), start = azimuths.front();
  for (size_t i = 1; i < azimuths.size(); ++i) {
    if (azimuths[i] - azimuths[i - 1] > widest_gap) {
      widest_gap = azimuths[i] - azimuths[i - 1];
      start = azimuths[i];
    }
  }
  auto unwrapped = [&](double azimuth) { return azimuth < start ? azimuth + 2 * M_PI : azimuth; };
  double azimuth_span = 0, elevation_min = M_PI, elevation_max = -M_PI;
  for (const Angles& a : angles) {
    azimuth_span = std::max(azimuth_span, unwrapped(a.azimuth) - start);
    elevation_min = std::min(elevation_min, a.elevation);
    elevation_max = std::max(elevation_max, a.elevation);
  }
  // A little room so that the extreme points fall inside the last cells, and no zero spans.
  const double floor_rad = 1e-4;
  azimuth_span = std::max(azimuth_span, floor_rad);
  const double elevation_span = std::max(elevation_max - elevation_min, floor_rad);
  const double step =
      std::sqrt(azimuth_span * elevation_span * kPointsPerCell / static_cast<double>(angles.size()));
  const cv::Size size = PictureSize(azimuth_span / step, elevation_span / step, options);
  const double step_across = azimuth_span / size.width, step_down = elevation_span / size.height;

  PictureLayout layout;
  layout.view = PictureView::kSphere;
  layout.cells = EmptyCells(scan, size);
  ScanGrid& grid = layout.cells.grid;
  for (int col = 0; col < size.width; ++col) grid.azimuth_rad.push_back(start + (col + 0.5) * step_across);
  for (int row = 0; row < size.height; ++row) {
    grid.elevation_rad.push_back(elevation_min + elevation_span - (row + 0.5) * step_down);
  }
  layout.cells.direction = DirectionsFromGrid(grid);
  std::vector<ProjectedPoint> projected;
  projected.reserve(angles.size());
  for (const Angles& a : angles) {
    projected.push_back({(unwrapped(a.azimuth) - start) / step_across,
                         (elevation_min + elevation_span - a.elevation) / step_down,
                         scan.range.at<float>(a.row, a.col), a.row, a.col});
  }
  layout.points = static_cast<int64_t>(projected.size());
  layout.points_kept = FillCells(scan, projected, &layout.cells);
  layout.picture_size = size;
  layout.pixel_width = step_across * kDegPerRad;
  layout.pixel_height = step_down * kDegPerRad;
  layout.pixel_unit = "deg";
  return layout;
}

// Orthographic views: the side of an automatic square is this many times the local point spacing (a Poisson
// spread of points leaves e^-4 = 2 % of the pixels uncovered at 2), and the spacing is read in a window holding
// at least kSpacingPoints points.
constexpr double kSplatPerSpacing = 2.0;
constexpr int kSpacingPoints = 8;
// ... and no automatic square is larger than this many times the median one.
constexpr double kMaxSplatPerMedian = 2.0;
constexpr int64_t kOrthographicBytesPerPixel = 100;

// Draws every projected point (u, v in pixels; `pixel_m` metres a pixel) as a square, the point nearest to the
// viewer winning each pixel (among points of one surface, the one whose pixel is nearest):
// squares of `point_size_px` > 0, or (0: automatic) of kSplatPerSpacing times the local spacing, at most
// kMaxSplatPerMedian times the median square. Fills `cells` through FillCells (one chosen point per pixel);
// returns the number of points that show on at least one pixel and sets the median square side in
// *median_splat_px.
int64_t SplatCells(const Scan& scan, const std::vector<ProjectedPoint>& projected, int point_size_px,
                   double pixel_m, Scan* cells, cv::Mat* source_cells, double* median_splat_px) {
  const int rows = cells->rows, cols = cells->cols;
  const int64_t count = static_cast<int64_t>(projected.size());
  std::vector<cv::Point> pixel(projected.size());
  for (int64_t i = 0; i < count; ++i) {
    pixel[i] = cv::Point(std::clamp(static_cast<int>(std::floor(projected[i].u)), 0, cols - 1),
                         std::clamp(static_cast<int>(std::floor(projected[i].v)), 0, rows - 1));
  }
  cv::Mat depth(rows, cols, CV_64F, cv::Scalar(std::numeric_limits<double>::infinity()));
  cv::Mat winner(rows, cols, CV_32S, cv::Scalar(-1));
  cv::Mat centre_distance(rows, cols, CV_32S, cv::Scalar(std::numeric_limits<int32_t>::max()));
  // Draws point i as a square of `side` pixels with the depth test. Points within the square's width in
  // metres of the best depth so far are taken as the same surface: there the point whose pixel is nearest
  // wins, so that neighbouring squares meet halfway (a sharp picture of the surface) rather than the
  // slightly nearer one covering the other; a point nearer by more (a crown over the ground) always wins.
  auto draw = [&](int64_t i, int side) {
    const double same_surface_m = side * pixel_m;
    const int low = -(side - 1) / 2, high = side / 2;  // side 1: the pixel itself; 2: it and the next
    for (int row = std::max(0, pixel[i].y + low); row <= std::min(rows - 1, pixel[i].y + high); ++row) {
      for (int col = std::max(0, pixel[i].x + low); col <= std::min(cols - 1, pixel[i].x + high); ++col) {
        double& best = depth.at<double>(row, col);
        int32_t& best_distance = centre_distance.at<int32_t>(row, col);
        const int32_t distance =
            (row - pixel[i].y) * (row - pixel[i].y) + (col - pixel[i].x) * (col - pixel[i].x);
        const double d = projected[i].depth;
        if (d < best - same_surface_m || (d <= best + same_surface_m && distance < best_distance)) {
          best = d;
          best_distance = distance;
          winner.at<int32_t>(row, col) = static_cast<int32_t>(i);
        }
      }
    }
  };
  std::vector<double> sides;
  if (point_size_px > 0) {
    for (int64_t i = 0; i < count; ++i) draw(i, point_size_px);
    *median_splat_px = point_size_px;
  } else {
    // Local spacing from the number of pixels with a point in a window around each point (an integral image;
    // pixels, not points, so that points stacked along the line of sight, a field seen edge-on from the
    // side, count once): the smallest window of 2w + 1 pixels (w = 1, 2, 4, ...) holding kSpacingPoints,
    // clipped to the picture.
    cv::Mat occupied(rows, cols, CV_64F, cv::Scalar(0));  // (cv::integral takes no 32-bit integers)
    for (const cv::Point& p : pixel) occupied.at<double>(p) = 1.0;
    cv::Mat sums;
    cv::integral(occupied, sums, CV_64F);
    // The largest square: twice the spacing the points would have spread evenly over the picture, and never
    // less than a 40th of its longer side.
    const double even_spacing_px = std::sqrt(static_cast<double>(rows) * cols / std::max<int64_t>(count, 1));
    const int max_side = std::max(
        {3, std::max(rows, cols) / 40, static_cast<int>(std::ceil(kSplatPerSpacing * even_spacing_px))});
    auto window_count = [&](const cv::Point& p, int w, int* area) {
      const int top = std::max(0, p.y - w), bottom = std::min(rows, p.y + w + 1);
      const int left = std::max(0, p.x - w), right = std::min(cols, p.x + w + 1);
      *area = (bottom - top) * (right - left);
      return sums.at<double>(bottom, right) - sums.at<double>(top, right) - sums.at<double>(bottom, left) +
             sums.at<double>(top, left);
    };
    sides.reserve(projected.size());
    for (int64_t i = 0; i < count; ++i) {
      int area = 1;
      double in_window = 1;
      for (int w = 1;; w *= 2) {
        in_window = window_count(pixel[i], w, &area);
        if (in_window >= kSpacingPoints || w >= max_side) break;  // (w >= max_side: the window is 2w + 1)
      }
      const double spacing_px = std::sqrt(area / std::max(in_window, 1.0));
      sides.push_back(
          std::clamp(std::ceil(kSplatPerSpacing * spacing_px), 1.0, static_cast<double>(max_side)));
    }
    // Isolated points (a river's few returns among many around it) stay small squares: a picture shows where
    // the data is sparse rather than paint it over with blocks.
    std::vector<double> sorted = sides;
    const double median = Median(&sorted);
    const double largest =
        std::min(static_cast<double>(max_side), std::max(3.0, kMaxSplatPerMedian * median));
    for (int64_t i = 0; i < count; ++i) draw(i, static_cast<int>(std::min(sides[i], largest)));
    *median_splat_px = std::min(median, largest);
  }
  // One chosen point per pixel, at the pixel's centre, for FillCells to copy.
  std::vector<ProjectedPoint> chosen;
  std::vector<uint8_t> shown(projected.size(), 0);
  source_cells->create(rows, cols, CV_32S);
  source_cells->setTo(-1);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const int32_t i = winner.at<int32_t>(row, col);
      if (i < 0) continue;
      shown[i] = 1;
      source_cells->at<int32_t>(row, col) = projected[i].row * scan.cols + projected[i].col;
      chosen.push_back({col + 0.5, row + 0.5, 0.0, projected[i].row, projected[i].col});
    }
  }
  FillCells(scan, chosen, cells);
  return std::count(shown.begin(), shown.end(), 1);
}

PictureLayout LayOutOrthographic(const Scan& scan, PictureView view, const PictureLayoutOptions& options) {
  // u to the right, v up, depth: smaller is nearer to the viewer.
  std::vector<ProjectedPoint> projected;
  double u_min = INFINITY, u_max = -INFINITY, v_min = INFINITY, v_max = -INFINITY;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      const Eigen::Vector3d p = WorldPointOfCell(scan, row, col);
      const ProjectedPoint point = view == PictureView::kTop ? ProjectedPoint{p.x(), p.y(), -p.z(), row, col}
                                   : view == PictureView::kSide
                                       ? ProjectedPoint{p.y(), p.z(), -p.x(), row, col}
                                       : ProjectedPoint{p.x(), p.z(), p.y(), row, col};
      u_min = std::min(u_min, point.u);
      u_max = std::max(u_max, point.u);
      v_min = std::min(v_min, point.v);
      v_max = std::max(v_max, point.v);
      projected.push_back(point);
    }
  }
  if (projected.empty()) ThrowNothingToProject(scan, view);
  // The window holds the 0.5-99.5 % quantiles on each axis and a quarter of their span around them (never
  // more than the points' extent): a few far stray points (a terrestrial scan's distant ground rings) would
  // otherwise shrink everything else to a corner, while the top of a thin post stays in. Points outside are
  // left out.
  auto quantile = [&](double fraction, bool along_u) {
    std::vector<double> values;
    values.reserve(projected.size());
    for (const ProjectedPoint& p : projected) values.push_back(along_u ? p.u : p.v);
    const size_t index =
        std::min(values.size() - 1, static_cast<size_t>(fraction * (values.size() - 1) + 0.5));
    std::nth_element(values.begin(), values.begin() + index, values.end());
    return values[index];
  };
  const double u_low = quantile(kWindowLow, true), u_high = quantile(kWindowHigh, true);
  const double v_low = quantile(kWindowLow, false), v_high = quantile(kWindowHigh, false);
  const double u_margin = kWindowMargin * (u_high - u_low), v_margin = kWindowMargin * (v_high - v_low);
  u_min = std::max(u_min, u_low - u_margin);
  u_max = std::min(u_max, u_high + u_margin);
  v_min = std::max(v_min, v_low - v_margin);
  v_max = std::min(v_max, v_high + v_margin);
  const int64_t all_points = static_cast<int64_t>(projected.size());
  std::erase_if(projected, [&](const ProjectedPoint& p) {
    return p.u < u_min || p.u > u_max || p.v < v_min || p.v > v_max;
  });
  const double floor_m = 1e-3;
  const double u_span = std::max(u_max - u_min, floor_m), v_span = std::max(v_max - v_min, floor_m);
  // Natural size: one point a pixel over the window; the squares close the gaps, so a picture is never
  // smaller than min_long_side_px on its longer side.
  double step = std::sqrt(u_span * v_span / static_cast<double>(projected.size()));
  const double long_side = std::max(u_span, v_span) / step;
  const double min_long_side = std::min(options.min_long_side_px, options.max_side_px);
  if (long_side < min_long_side) step *= long_side / min_long_side;
  const cv::Size size = PictureSize(u_span / step, v_span / step, options);
  const double step_across = u_span / size.width, step_down = v_span / size.height;
  for (ProjectedPoint& p : projected) {
    p.u = (p.u - u_min) / step_across;
    p.v = (v_min + v_span - p.v) / step_down;
  }
  // The cells' channels (about 64 bytes a pixel), the squares' buffers (32) and the source cells (4): a given
  // size is checked before anything of that size is allocated.
  CheckMemoryBudget(
      SaturatingBytes(static_cast<int64_t>(size.width) * size.height, kOrthographicBytesPerPixel),
      fmt::format("{}a {} view of {} x {} pixels", scan.name.empty() ? "" : scan.name + ": ", ToString(view),
                  size.width, size.height));
  PictureLayout layout;
  layout.view = view;
  layout.cells = EmptyCells(scan, size);
  layout.points = all_points;
  layout.points_kept = SplatCells(scan, projected, options.point_size_px, std::max(step_across, step_down),
                                  &layout.cells, &layout.source_cells, &layout.splat_px);
  layout.splat_automatic = options.point_size_px == 0;
  layout.picture_size = size;
  layout.pixel_width = step_across;
  layout.pixel_height = step_down;
  layout.pixel_unit = "m";
  layout.left_m = u_min;
  layout.top_m = v_min + v_span;
  return layout;
}

PictureLayout LayOutGrid(const Scan& scan, const PictureLayoutOptions& options) {
  PictureLayout layout;
  layout.view = PictureView::kGrid;
  layout.cells = scan;
  const cv::Vec2d steps = NativeStepsRad(scan);
  double natural_width = scan.cols, natural_height = scan.rows;
  if (options.aspect == PixelAspect::kSquare && steps[0] > 0 && steps[1] > 0) {
    // The finer step becomes the pixel: nothing is lost, the coarser direction repeats pixels.
    const double pixel = std::min(steps[0], steps[1]);
    natural_width = scan.cols * steps[0] / pixel;
    natural_height = scan.rows * steps[1] / pixel;
  }
  const bool one_per_ray = options.aspect == PixelAspect::kNative && options.width_px == 0 &&
                           options.height_px == 0;  // native: never capped
  layout.picture_size = one_per_ray ? cv::Size(std::max(scan.cols, 1), std::max(scan.rows, 1))
                                    : PictureSize(natural_width, natural_height, options);
  layout.pixel_width = steps[0] * scan.cols / layout.picture_size.width * kDegPerRad;
  layout.pixel_height = steps[1] * scan.rows / layout.picture_size.height * kDegPerRad;
  layout.pixel_unit = "deg";
  return layout;
}

}  // namespace

void PictureLayoutOptions::Check() const { Validate(*this); }

bool IsUnorganized(const Scan& scan) {
  return (scan.rows == 1 || scan.cols == 1) && scan.num_cells() > 1 && scan.grid.azimuth_rad.empty();
}

cv::Vec2d NativeStepsRad(const Scan& scan) {
  const ScanGrid& grid = scan.grid;
  if (static_cast<int>(grid.azimuth_rad.size()) == scan.cols &&
      static_cast<int>(grid.elevation_rad.size()) == scan.rows && scan.cols > 1 && scan.rows > 1) {
    return {std::abs(grid.azimuth_rad.back() - grid.azimuth_rad.front()) / (scan.cols - 1),
            std::abs(grid.elevation_rad.front() - grid.elevation_rad.back()) / (scan.rows - 1)};
  }
  // No grid: the median angle between neighbouring rays that both returned.
  std::vector<double> across, down;
  const RayDirections rays(scan);
  auto direction = [&](int row, int col) {
    const cv::Vec3f d = rays(row, col);
    return Eigen::Vector3f(d[0], d[1], d[2]);
  };
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      if (col + 1 < scan.cols && scan.valid.at<uint8_t>(row, col + 1)) {
        double step = std::abs(AzimuthOf(direction(row, col + 1)) - AzimuthOf(direction(row, col)));
        if (step > M_PI) step = 2 * M_PI - step;
        across.push_back(step);
      }
      if (row + 1 < scan.rows && scan.valid.at<uint8_t>(row + 1, col)) {
        down.push_back(std::abs(ElevationOf(direction(row, col)) - ElevationOf(direction(row + 1, col))));
      }
    }
  }
  return {Median(&across), Median(&down)};
}

PictureLayout LayOutPicture(const Scan& scan, const PictureLayoutOptions& options) {
  options.Check();
  CheckScan(scan);
  PictureView view = options.view;
  if (view == PictureView::kAuto) view = IsUnorganized(scan) ? PictureView::kSphere : PictureView::kGrid;
  switch (view) {
    case PictureView::kSphere:
      return LayOutSphere(scan, options);
    case PictureView::kTop:
    case PictureView::kFront:
    case PictureView::kSide:
      return LayOutOrthographic(scan, view, options);
    case PictureView::kAuto:
    case PictureView::kGrid:
      break;
  }
  return LayOutGrid(scan, options);
}

PictureLayoutSummary SummarizeLayout(const PictureLayout& layout) {
  PictureLayoutSummary summary;
  summary.view = layout.view;
  summary.description = layout.Describe();
  summary.pixel_width = layout.pixel_width;
  summary.pixel_height = layout.pixel_height;
  summary.pixel_unit = layout.pixel_unit;
  summary.source_rows = layout.cells.rows;
  summary.source_cols = layout.cells.cols;
  if (layout.view != PictureView::kGrid) {
    summary.points = layout.points;
    summary.points_kept = layout.points_kept;
  }
  if (layout.splat_px > 0) {
    summary.point_size_px = layout.splat_px;
    summary.point_size = layout.splat_automatic ? "twice the local point spacing (median)" : "--point-size";
  }
  return summary;
}

std::string PictureLayout::Describe() const {
  const std::string size = fmt::format("{} x {}", picture_size.width, picture_size.height);
  const std::string pixel = pixel_unit == "deg"
                                ? fmt::format("{:.4g}° x {:.4g}°", pixel_width, pixel_height)
                                : fmt::format("{:.4g} m x {:.4g} m", pixel_width, pixel_height);
  switch (view) {
    case PictureView::kSphere:
      return fmt::format(
          "unorganized cloud of {} points projected onto a spherical grid around the scanner position: {} "
          "pixels of {}; {} points shown, {} hidden behind nearer ones",
          points, size, pixel, points_kept, points - points_kept);
    case PictureView::kTop:
    case PictureView::kFront:
    case PictureView::kSide:
      return fmt::format(
          "{} points projected orthographically ({} view, world frame): {} pixels of {}, each point a "
          "square of {}{:.3g} px{}; {} points shown, {} hidden behind nearer ones or outside the window",
          points, ToString(view), size, pixel, splat_automatic ? "about " : "", splat_px,
          splat_automatic ? " (twice the local point spacing)" : "", points_kept, points - points_kept);
    case PictureView::kAuto:
    case PictureView::kGrid:
      break;
  }
  return fmt::format("{} x {} rays shown as {} pixels of {}", cells.cols, cells.rows, size, pixel);
}

Eigen::Vector3d TowardViewer(PictureView view) {
  switch (view) {
    case PictureView::kTop:
      return Eigen::Vector3d::UnitZ();
    case PictureView::kFront:
      return -Eigen::Vector3d::UnitY();
    case PictureView::kSide:
      return Eigen::Vector3d::UnitX();
    case PictureView::kAuto:
    case PictureView::kGrid:
    case PictureView::kSphere:
      break;
  }
  return Eigen::Vector3d::Zero();
}

cv::Mat ResampleNearest(const cv::Mat& image, cv::Size size) {
  if (image.size() == size) return image;
  cv::Mat resampled(size, image.type());
  const size_t element = image.elemSize();
  std::vector<int> source_col(size.width);
  for (int col = 0; col < size.width; ++col) {
    source_col[col] = std::min(image.cols - 1, static_cast<int>((col + 0.5) * image.cols / size.width));
  }
  for (int row = 0; row < size.height; ++row) {
    const int source_row = std::min(image.rows - 1, static_cast<int>((row + 0.5) * image.rows / size.height));
    const uint8_t* in = image.ptr<uint8_t>(source_row);
    uint8_t* out = resampled.ptr<uint8_t>(row);
    for (int col = 0; col < size.width; ++col) {
      std::memcpy(out + col * element, in + source_col[col] * element, element);
    }
  }
  return resampled;
}

}  // namespace lidarshop
