#include "lidarshop/render/picture_mapping.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/io/image_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/json_input.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

constexpr const char* kLayoutFormat = "lidarshop picture layout";
constexpr int kLayoutVersion = 1;
// Widening of a sphere cell's pixels, at most this many pixels on each side.
constexpr int kMaxFootprintRadiusPx = 16;
constexpr int kMaxLayoutPointSizePx = 32;  // PictureLayoutOptions::point_size_px's range

bool IsOrthographic(PictureView view) {
  return view == PictureView::kTop || view == PictureView::kFront || view == PictureView::kSide;
}

// An orthographic picture: each painted pixel votes for the cell whose point it shows; a cell takes its most
// frequent non-zero vote.
cv::Mat CellsFromOrthographic(const Scan& scan, const PictureMapping& mapping, const cv::Mat& picture) {
  LIDARSHOP_CHECK(mapping.source_cells.type() == CV_32S &&
                  mapping.source_cells.size() == mapping.picture_size);
  std::vector<std::pair<int32_t, uint8_t>> votes;  // (cell, value), sorted below
  for (int y = 0; y < mapping.picture_size.height; ++y) {
    const uint8_t* painted = picture.ptr<uint8_t>(y);
    const int32_t* shown = mapping.source_cells.ptr<int32_t>(y);
    for (int x = 0; x < mapping.picture_size.width; ++x) {
      if (painted[x] != 0 && shown[x] >= 0) votes.emplace_back(shown[x], painted[x]);
    }
  }
  std::sort(votes.begin(), votes.end());
  cv::Mat cells(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  const int64_t cell_count = static_cast<int64_t>(scan.rows) * scan.cols;
  for (size_t begin = 0; begin < votes.size();) {
    const int32_t cell = votes[begin].first;
    size_t end = begin;
    uint8_t best = 0;
    size_t best_count = 0;
    while (end < votes.size() && votes[end].first == cell) {
      size_t run = end;
      while (run < votes.size() && votes[run] == votes[end]) ++run;
      if (run - end > best_count) best_count = run - end, best = votes[end].second;
      end = run;
    }
    LIDARSHOP_CHECK(cell < cell_count);
    cells.at<uint8_t>(cell / scan.cols, cell % scan.cols) = best;
    begin = end;
  }
  return cells;
}

// The most frequent non-zero value of picture[y0..y1][x0..x1] (inclusive), 0 when all are 0; ties go to the
// value met first.
uint8_t MostFrequentNonZero(const cv::Mat& picture, int x0, int x1, int y0, int y1) {
  if (x0 == x1 && y0 == y1) return picture.at<uint8_t>(y0, x0);
  std::pair<uint8_t, int> found[4] = {};
  int distinct = 0;
  for (int y = y0; y <= y1; ++y) {
    const uint8_t* row = picture.ptr<uint8_t>(y);
    for (int x = x0; x <= x1; ++x) {
      const uint8_t value = row[x];
      if (value == 0) continue;
      int k = 0;
      while (k < distinct && found[k].first != value) ++k;
      if (k == distinct) {
        if (distinct == 4) continue;  // strokes and masks hold at most two values
        found[distinct++] = {value, 0};
      }
      ++found[k].second;
    }
  }
  uint8_t best = 0;
  int best_count = 0;
  for (int k = 0; k < distinct; ++k) {
    if (found[k].second > best_count) {
      best = found[k].first;
      best_count = found[k].second;
    }
  }
  return best;
}

// For every cell of an axis of `cells` shown by `pixels` pixels (ResampleNearest: pixel p shows cell
// floor((p + 0.5) * cells / pixels)): the first and last pixel showing it, or the pixel holding its centre.
std::vector<std::pair<int, int>> PixelsOfCells(int cells, int pixels) {
  std::vector<std::pair<int, int>> range(static_cast<size_t>(cells), {-1, -1});
  for (int p = 0; p < pixels; ++p) {
    const int cell = std::min(cells - 1, static_cast<int>((p + 0.5) * cells / pixels));
    auto& r = range[static_cast<size_t>(cell)];
    if (r.first < 0) r.first = p;
    r.second = p;
  }
  for (int cell = 0; cell < cells; ++cell) {
    auto& r = range[static_cast<size_t>(cell)];
    if (r.first >= 0) continue;
    const int p = std::clamp(static_cast<int>((cell + 0.5) * pixels / cells), 0, pixels - 1);
    r = {p, p};
  }
  return range;
}

double NumberField(const nlohmann::json& doc, const char* key, const std::string& what) {
  if (!doc.contains(key) || !doc[key].is_number()) ThrowInputError(what, "", key, "missing or not a number");
  const double value = doc[key].get<double>();
  if (!std::isfinite(value)) ThrowInputError(what, "", key, "must be finite");
  return value;
}

int SizeField(const nlohmann::json& doc, const char* key, const std::string& what) {
  if (!doc.contains(key) || !doc[key].is_number_integer()) {
    ThrowInputError(what, "", key, "missing or not an integer");
  }
  const int64_t value = doc[key].get<int64_t>();
  if (value < 1 || value > (int64_t{1} << 24)) ThrowInputError(what, "", key, "must be in [1, 2^24]");
  return static_cast<int>(value);
}

}  // namespace

bool HasCellMapping(PictureView view) { return view != PictureView::kAuto; }

PictureMapping MappingOfLayout(const PictureLayout& layout, const Scan& scan, cv::Size image_size) {
  LIDARSHOP_CHECK(HasCellMapping(layout.view));
  PictureMapping mapping;
  mapping.view = layout.view;
  mapping.scan_rows = scan.rows;
  mapping.scan_cols = scan.cols;
  mapping.picture_size = layout.picture_size;
  mapping.image_size = image_size.empty() ? layout.picture_size : image_size;
  mapping.pixel_width = layout.pixel_width;
  mapping.pixel_height = layout.pixel_height;
  mapping.pixel_unit = layout.pixel_unit;
  if (layout.view == PictureView::kSphere) {
    // The cells' grid holds pixel centres: start + (k + 0.5) * step.
    const std::vector<double>& azimuths = layout.cells.grid.azimuth_rad;
    const std::vector<double>& elevations = layout.cells.grid.elevation_rad;
    LIDARSHOP_CHECK(!azimuths.empty() && !elevations.empty());
    mapping.azimuth_step_rad = azimuths.size() > 1
                                   ? (azimuths.back() - azimuths.front()) / (azimuths.size() - 1)
                                   : layout.pixel_width * M_PI / 180.0;
    mapping.elevation_step_rad = elevations.size() > 1
                                     ? (elevations.front() - elevations.back()) / (elevations.size() - 1)
                                     : layout.pixel_height * M_PI / 180.0;
    mapping.azimuth_left_rad = azimuths.front() - 0.5 * mapping.azimuth_step_rad;
    mapping.elevation_top_rad = elevations.front() + 0.5 * mapping.elevation_step_rad;
  }
  if (IsOrthographic(layout.view)) {
    mapping.point_size_px = layout.splat_automatic ? 0 : static_cast<int>(layout.splat_px);
    mapping.source_cells = layout.source_cells;
    mapping.left_m = layout.left_m;
    mapping.top_m = layout.top_m;
  }
  return mapping;
}

nlohmann::ordered_json PictureMappingJson(const PictureMapping& mapping) {
  nlohmann::ordered_json json;
  json["format"] = kLayoutFormat;
  json["version"] = kLayoutVersion;
  json["scan_rows"] = mapping.scan_rows;
  json["scan_cols"] = mapping.scan_cols;
  json["view"] = ToString(mapping.view);
  json["image_width"] = mapping.image_size.width;
  json["image_height"] = mapping.image_size.height;
  json["picture_width"] = mapping.picture_size.width;
  json["picture_height"] = mapping.picture_size.height;
  json["pixel_width"] = mapping.pixel_width;
  json["pixel_height"] = mapping.pixel_height;
  json["pixel_unit"] = mapping.pixel_unit;
  if (mapping.view == PictureView::kSphere) {
    json["azimuth_left_rad"] = mapping.azimuth_left_rad;
    json["elevation_top_rad"] = mapping.elevation_top_rad;
    json["azimuth_step_rad"] = mapping.azimuth_step_rad;
    json["elevation_step_rad"] = mapping.elevation_step_rad;
  }
  if (IsOrthographic(mapping.view)) {
    json["point_size_px"] = mapping.point_size_px;
    json["left_m"] = mapping.left_m;
    json["top_m"] = mapping.top_m;
  }
  return json;
}

nlohmann::ordered_json LayoutFileJson(const PictureLayout& layout, const Scan& scan, cv::Size image_size) {
  return PictureMappingJson(MappingOfLayout(layout, scan, image_size));
}

PictureMapping ParsePictureMapping(const std::string& text, const std::string& what) {
  const nlohmann::json doc = ParseJsonInput(text, what);
  if (!doc.is_object() || !doc.contains("format") || doc["format"] != kLayoutFormat) {
    ThrowInputError(what, "", "format",
                    fmt::format("not a picture layout file (\"format\": \"{}\")", kLayoutFormat));
  }
  if (!doc.contains("version") || doc["version"] != kLayoutVersion) {
    ThrowInputError(what, "", "version", fmt::format("lidarshop reads version {}", kLayoutVersion));
  }
  PictureMapping mapping;
  if (!doc.contains("view") || !doc["view"].is_string()) ThrowInputError(what, "", "view", "missing");
  const std::string view = doc["view"].get<std::string>();
  std::optional<PictureView> parsed;
  for (const EnumInfo::Choice& choice : EnumInfoOf<PictureView>().choices) {
    if (choice.name == view && HasCellMapping(static_cast<PictureView>(choice.value))) {
      parsed = static_cast<PictureView>(choice.value);
    }
  }
  if (!parsed) {
    ThrowInputError(what, "", "view", fmt::format("'{}' is not grid, sphere, top, front or side", view));
  }
  mapping.view = *parsed;
  mapping.scan_rows = SizeField(doc, "scan_rows", what);
  mapping.scan_cols = SizeField(doc, "scan_cols", what);
  mapping.image_size = cv::Size(SizeField(doc, "image_width", what), SizeField(doc, "image_height", what));
  mapping.picture_size =
      cv::Size(SizeField(doc, "picture_width", what), SizeField(doc, "picture_height", what));
  if (mapping.picture_size.width > mapping.image_size.width ||
      mapping.picture_size.height > mapping.image_size.height) {
    ThrowInputError(what, "", "picture_width", "the picture is larger than the image holding it");
  }
  mapping.pixel_width = NumberField(doc, "pixel_width", what);
  mapping.pixel_height = NumberField(doc, "pixel_height", what);
  if (doc.contains("pixel_unit") && doc["pixel_unit"].is_string()) mapping.pixel_unit = doc["pixel_unit"];
  if (mapping.view == PictureView::kSphere) {
    mapping.azimuth_left_rad = NumberField(doc, "azimuth_left_rad", what);
    mapping.elevation_top_rad = NumberField(doc, "elevation_top_rad", what);
    mapping.azimuth_step_rad = NumberField(doc, "azimuth_step_rad", what);
    mapping.elevation_step_rad = NumberField(doc, "elevation_step_rad", what);
    if (!(mapping.azimuth_step_rad > 0) || !(mapping.elevation_step_rad > 0) ||
        mapping.azimuth_step_rad * mapping.picture_size.width > 2 * M_PI + 1e-6) {
      ThrowInputError(what, "", "azimuth_step_rad",
                      "the steps must be positive and the picture at most one turn wide");
    }
  }
  if (IsOrthographic(mapping.view)) {
    if (doc.contains("point_size_px")) {
      if (!doc["point_size_px"].is_number_integer() || doc["point_size_px"].get<int64_t>() < 0 ||
          doc["point_size_px"].get<int64_t>() > kMaxLayoutPointSizePx) {
        ThrowInputError(what, "", "point_size_px",
                        fmt::format("must be an integer in [0, {}]", kMaxLayoutPointSizePx));
      }
      mapping.point_size_px = doc["point_size_px"].get<int>();
    }
    mapping.left_m = NumberField(doc, "left_m", what);
    mapping.top_m = NumberField(doc, "top_m", what);
  }
  return mapping;
}

std::string LayoutFilePath(const std::string& picture_path) { return picture_path + ".layout.json"; }

cv::Mat CellsFromPicture(const Scan& scan, const PictureMapping& mapping, const cv::Mat& picture) {
  CheckScan(scan);
  LIDARSHOP_CHECK(scan.rows == mapping.scan_rows && scan.cols == mapping.scan_cols);
  LIDARSHOP_CHECK(picture.type() == CV_8U && picture.size() == mapping.image_size);
  if (IsOrthographic(mapping.view)) return CellsFromOrthographic(scan, mapping, picture);
  const int width = mapping.picture_size.width, height = mapping.picture_size.height;
  cv::Mat cells(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  if (mapping.view == PictureView::kGrid) {
    const auto across = PixelsOfCells(scan.cols, width), down = PixelsOfCells(scan.rows, height);
    for (int row = 0; row < scan.rows; ++row) {
      const auto [y0, y1] = down[static_cast<size_t>(row)];
      uint8_t* out = cells.ptr<uint8_t>(row);
      for (int col = 0; col < scan.cols; ++col) {
        const auto [x0, x1] = across[static_cast<size_t>(col)];
        out[col] = MostFrequentNonZero(picture, x0, x1, y0, y1);
      }
    }
    return cells;
  }
  LIDARSHOP_CHECK(mapping.view == PictureView::kSphere);
  // Pixels finer than the rays: a cell speaks for the pixels up to half a ray step around its own.
  int radius_x = 0, radius_y = 0;
  if (!IsUnorganized(scan)) {
    const cv::Vec2d steps = NativeStepsRad(scan);
    radius_x =
        std::clamp(static_cast<int>(0.5 * steps[0] / mapping.azimuth_step_rad), 0, kMaxFootprintRadiusPx);
    radius_y =
        std::clamp(static_cast<int>(0.5 * steps[1] / mapping.elevation_step_rad), 0, kMaxFootprintRadiusPx);
  }
  const RayDirections rays(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      cv::Vec3f d = rays(row, col);
      if (scan.valid.at<uint8_t>(row, col) && scan.range.at<float>(row, col) > 0) {
        d = scan.point.at<cv::Vec3f>(row, col);  // the projection of LayOutSphere: the point's own direction
      }
      if (d == cv::Vec3f(0, 0, 0)) continue;
      double azimuth = std::atan2(d[0], d[1]);
      if (azimuth < mapping.azimuth_left_rad) azimuth += 2 * M_PI;
      const double elevation = std::atan2(d[2], std::hypot(d[0], d[1]));
      const double u = (azimuth - mapping.azimuth_left_rad) / mapping.azimuth_step_rad;
      const double v = (mapping.elevation_top_rad - elevation) / mapping.elevation_step_rad;
      // The extreme points fall on the far edges (LayOutSphere keeps them in the last pixel); rays farther
      // out are not in the picture.
      if (u < -1 || v < -1 || u > width + 1 || v > height + 1) continue;
      const int x = std::clamp(static_cast<int>(std::floor(u)), 0, width - 1);
      const int y = std::clamp(static_cast<int>(std::floor(v)), 0, height - 1);
      cells.at<uint8_t>(row, col) =
          MostFrequentNonZero(picture, std::max(0, x - radius_x), std::min(width - 1, x + radius_x),
                              std::max(0, y - radius_y), std::min(height - 1, y + radius_y));
    }
  }
  return cells;
}

namespace {

// A top / front / side mapping read from its file gets the cell each pixel shows by laying the view out again
// at the file's sizes (the same scan and sizes give the same picture); a scan that gives another picture (its
// points moved since) is refused rather than mapped onto the wrong cells.
PictureMapping WithSourceCells(const Scan& scan, PictureMapping mapping, const std::string& file) {
  PictureLayoutOptions options;
  options.view = mapping.view;
  options.width_px = mapping.picture_size.width;
  options.height_px = mapping.picture_size.height;
  options.point_size_px = mapping.point_size_px;
  const PictureLayout layout = LayOutPicture(scan, options);
  const auto same = [](double a, double b) {
    return std::abs(a - b) <= 1e-9 * std::max({std::abs(a), std::abs(b), 1.0});
  };
  if (layout.picture_size != mapping.picture_size || !same(layout.pixel_width, mapping.pixel_width) ||
      !same(layout.pixel_height, mapping.pixel_height) || !same(layout.left_m, mapping.left_m) ||
      !same(layout.top_m, mapping.top_m)) {
    ThrowInputError(
        file, "", "left_m",
        fmt::format("the {} view of this scan has pixels of {:.6g} m x {:.6g} m from ({:.6f}, "
                    "{:.6f}), the layout file {:.6g} m x {:.6g} m from ({:.6f}, {:.6f}): the "
                    "picture was drawn of other points; render it again",
                    ToString(mapping.view), layout.pixel_width, layout.pixel_height, layout.left_m,
                    layout.top_m, mapping.pixel_width, mapping.pixel_height, mapping.left_m, mapping.top_m));
  }
  mapping.source_cells = layout.source_cells;
  return mapping;
}

}  // namespace

std::optional<PictureMapping> FindPictureMapping(const Scan& scan, const std::string& picture_path,
                                                 cv::Size picture_size, const std::string& layout_path,
                                                 const std::string& what_scan) {
  if (picture_size == cv::Size(scan.cols, scan.rows)) return std::nullopt;
  // The layout file, given or beside the picture.
  const std::string beside = LayoutFilePath(picture_path);
  std::error_code error;
  const std::string file =
      !layout_path.empty() ? layout_path : (std::filesystem::is_regular_file(beside, error) ? beside : "");
  if (!file.empty()) {
    constexpr int64_t kMaxLayoutBytes = int64_t{1} << 20;
    const PictureMapping mapping = ParsePictureMapping(ReadRegularFile(file, kMaxLayoutBytes), file);
    if (mapping.scan_rows != scan.rows || mapping.scan_cols != scan.cols) {
      ThrowInputError(file, "", "scan_cols",
                      fmt::format("the layout is of a scan of {} x {} cells, {} has {} x {} (cols x rows)",
                                  mapping.scan_cols, mapping.scan_rows, what_scan, scan.cols, scan.rows));
    }
    if (mapping.image_size != picture_size) {
      ThrowInputError(
          picture_path, "", "",
          fmt::format("{} x {} pixels but its layout file {} describes {} x {}", picture_size.width,
                      picture_size.height, file, mapping.image_size.width, mapping.image_size.height));
    }
    if (IsOrthographic(mapping.view)) return WithSourceCells(scan, mapping, file);
    return mapping;
  }
  // Render's default layout at the picture's width or height (square pixels).
  constexpr int kLargestPicture = 16384;  // PictureLayoutOptions' limit
  PictureLayoutOptions options;
  options.width_px = std::clamp(picture_size.width, 1, kLargestPicture);
  const PictureLayout at_width = LayOutPicture(scan, options);
  if (at_width.picture_size == picture_size) return MappingOfLayout(at_width, scan);
  options.width_px = 0;
  options.height_px = std::clamp(picture_size.height, 1, kLargestPicture);
  const PictureLayout at_height = LayOutPicture(scan, options);
  if (at_height.picture_size == picture_size) return MappingOfLayout(at_height, scan);
  const PictureLayout automatic = LayOutPicture(scan, PictureLayoutOptions());
  ThrowInputError(
      picture_path, "", "",
      fmt::format("{} x {} pixels fits neither {}'s grid ({} x {} cells) nor a picture `lidarshop render` "
                  "writes of it ({} x {} by default, or any width with that aspect: {} x {} at this width); "
                  "paint strokes or masks on `lidarshop render {} -o PICTURE.png` (any --width, --height), "
                  "or give the "
                  "picture's layout file with --layout (render writes it beside the picture as "
                  "PICTURE.png.layout.json)",
                  picture_size.width, picture_size.height, what_scan, scan.cols, scan.rows,
                  automatic.picture_size.width, automatic.picture_size.height, at_width.picture_size.width,
                  at_width.picture_size.height, what_scan));
}

cv::Mat ReadMaskForScan(const std::string& path, const Scan& scan, const std::string& layout_path,
                        const std::string& what_scan) {
  const cv::Mat mask = ReadMask(path, cv::Size(), what_scan);
  const std::optional<PictureMapping> mapping =
      FindPictureMapping(scan, path, mask.size(), layout_path, what_scan);
  if (!mapping) return mask;
  return CellsFromPicture(scan, *mapping, mask);
}

}  // namespace lidarshop
