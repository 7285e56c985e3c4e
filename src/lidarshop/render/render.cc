#include "lidarshop/render/render.h"

#include <charconv>
#include <cmath>
#include <set>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/render/render_shading.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

void RenderOptions::Check() const {
  // NaN means "from the data"; anything else must be a finite value a colour can stand for.
  for (const auto& [name, value] : {std::pair{"min_value", min_value}, std::pair{"max_value", max_value}}) {
    CheckOption(std::isnan(value) || std::abs(value) <= 1e12,
                fmt::format("RenderOptions: {} must be finite and within ±1e12, got {}", name, value));
  }
  if (!std::isnan(min_value) && !std::isnan(max_value)) {
    CheckOption(
        min_value < max_value,
        fmt::format("RenderOptions: min_value ({}) must be below max_value ({})", min_value, max_value));
  }
}

cv::Mat EstimateGridNormals(const Scan& scan) {
  cv::Mat normals(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0));
  auto valid = [&](int row, int col) {
    return row >= 0 && col >= 0 && row < scan.rows && col < scan.cols &&
           scan.valid.at<uint8_t>(row, col) != 0;
  };
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!valid(row, col)) continue;
      // One-sided differences where a neighbour is missing.
      const int left = valid(row, col - 1) ? col - 1 : col, right = valid(row, col + 1) ? col + 1 : col;
      const int up = valid(row - 1, col) ? row - 1 : row, down = valid(row + 1, col) ? row + 1 : row;
      if (left == right || up == down) continue;
      const cv::Vec3f horizontal = scan.point.at<cv::Vec3f>(row, right) - scan.point.at<cv::Vec3f>(row, left);
      const cv::Vec3f vertical = scan.point.at<cv::Vec3f>(up, col) - scan.point.at<cv::Vec3f>(down, col);
      cv::Vec3f normal = horizontal.cross(vertical);
      const float norm = static_cast<float>(cv::norm(normal));
      if (norm == 0) continue;
      normal /= norm;
      if (normal.dot(scan.point.at<cv::Vec3f>(row, col)) > 0) normal = -normal;  // towards the scanner
      normals.at<cv::Vec3f>(row, col) = normal;
    }
  }
  return normals;
}

namespace {

cv::Vec3b NormalColor(const cv::Vec3f& n) {
  cv::Vec3b out;
  for (int k = 0; k < 3; ++k) out[k] = cv::saturate_cast<uint8_t>((n[k] + 1.0f) * 127.5f);
  return out;
}

// World z of every cell, metres (NaN where the ray did not return).
cv::Mat ElevationValues(const Scan& scan) {
  cv::Mat values(scan.rows, scan.cols, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const Eigen::Vector4d z_row = scan.world_from_scanner.row(2).transpose();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(row, col);
      values.at<float>(row, col) = static_cast<float>(z_row.dot(Eigen::Vector4d(p[0], p[1], p[2], 1.0)));
    }
  }
  return values;
}

void ThrowNoIntensity(const Scan& scan) {
  // Name what there is instead (leaving out range, valid and direction, which every scan has).
  std::vector<std::string> present;
  for (const std::string& name : ChannelNames(scan)) {
    if (name != "range" && name != "valid" && name != "direction") present.push_back(name);
  }
  throw InputError(fmt::format("{} has no intensity channel; it has: {}",
                               scan.name.empty() ? "the scan" : scan.name, fmt::join(present, ", ")));
}

// The labels present among the valid cells, at most 40 (a legend, not a catalogue).
std::vector<int32_t> PresentLabels(const Scan& cells) {
  std::set<int32_t> present;
  for (int row = 0; row < cells.rows; ++row) {
    for (int col = 0; col < cells.cols; ++col) {
      if (cells.valid.at<uint8_t>(row, col)) present.insert(cells.label.at<int32_t>(row, col));
    }
  }
  std::vector<int32_t> shown(present.begin(), present.end());
  if (shown.size() > 40) shown.resize(40);
  return shown;
}

// The cells' colours, one pixel per cell, no-return cells left black (painted after resampling), and the
// swatch legend's lines.
RenderResult ColorCells(const Scan& scan, const RenderOptions& options) {
  RenderResult result;
  auto metric = [&](const cv::Mat& values, ColorMap default_map, const std::string& unit) {
    const ColorMap map = options.color_map.value_or(default_map);
    ColorScale scale = AutoScale(values, scan.valid, map, unit);  // 1-99 % quantiles
    if (!std::isnan(options.min_value)) scale.min_value = options.min_value;
    if (!std::isnan(options.max_value)) scale.max_value = options.max_value;
    if (scale.max_value <= scale.min_value) scale.max_value = scale.min_value + 1e-6;
    result.image = ApplyColorMap(values, scan.valid, scale);
    result.scale = scale;
  };
  RenderChannel channel = options.channel;
  if (channel == RenderChannel::kLabels && HoldsAsprsClasses(scan)) channel = RenderChannel::kClassification;
  switch (channel) {
    case RenderChannel::kRange:
      metric(scan.range, ColorMap::kViridis, "m");
      break;
    case RenderChannel::kElevation:
      metric(ElevationValues(scan), ColorMap::kViridis, "m");
      break;
    case RenderChannel::kIntensity: {
      if (!scan.has_intensity()) ThrowNoIntensity(scan);
      const auto [low, high] = IntensityFileRange(scan);
      cv::Mat values = scan.intensity;
      if (low != 0.0 || high != 1.0) values = scan.intensity * (high - low) + low;
      metric(values, ColorMap::kGray, "");
      break;
    }
    case RenderChannel::kRgb:
      if (!scan.has_color()) ThrowInputError(scan.name, "", "rgb", "the scan has no colour channel");
      result.image = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
      scan.color.copyTo(result.image, scan.valid);
      break;
    case RenderChannel::kNormals: {
      const cv::Mat normals = scan.normal.empty() ? EstimateGridNormals(scan) : scan.normal;
      result.image = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
      for (int row = 0; row < scan.rows; ++row) {
        for (int col = 0; col < scan.cols; ++col) {
          const cv::Vec3f& n = normals.at<cv::Vec3f>(row, col);
          if (!scan.valid.at<uint8_t>(row, col) || n == cv::Vec3f(0, 0, 0)) continue;
          result.image.at<cv::Vec3b>(row, col) = NormalColor(n);
        }
      }
      break;
    }
    case RenderChannel::kLabels:
      if (scan.label.empty()) ThrowInputError(scan.name, "", "labels", "the scan has no label channel");
      result.image = ColorLabels(scan.label, scan.valid);
      for (const int32_t label : PresentLabels(scan)) {
        const auto name = options.label_names.find(label);
        const bool named = name != options.label_names.end() && !name->second.empty();
        result.legend_lines.push_back(label < 0 ? (named ? name->second : "none")
                                      : named   ? fmt::format("{}  {}", label, name->second)
                                                : fmt::format("label {}", label));
      }
      break;
    case RenderChannel::kClassification:
      if (scan.label.empty()) {
        ThrowInputError(scan.name, "", "classification", "the scan has no classification (label) channel");
      }
      result.image = ColorAsprsClasses(scan.label, scan.valid);
      for (const int32_t code : PresentLabels(scan)) {
        result.legend_lines.push_back(fmt::format("{}  {}", code, AsprsClassName(code)));
      }
      break;
    case RenderChannel::kValid:
      result.image = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
      result.image.setTo(cv::Scalar::all(255), scan.valid);
      break;
  }
  return result;
}

// The coloured cells resampled to `size`, the no-return checker, and the legend.
RenderResult FinishPicture(const Scan& cells, RenderResult colored, cv::Size size,
                           const RenderOptions& options, const std::string& no_data_text = "no return") {
  colored.image = ResampleNearest(colored.image, size);
  const cv::Mat valid = ResampleNearest(cells.valid, size);
  const bool any_no_return = options.channel != RenderChannel::kValid &&
                             static_cast<size_t>(cv::countNonZero(valid)) < valid.total();
  if (any_no_return) PaintNoReturn(&colored.image, valid);
  if (!options.legend) return colored;
  cv::Mat legend;
  if (colored.scale) {
    legend = ColorScaleBar(*colored.scale, size.height);
  } else if (options.channel == RenderChannel::kLabels || options.channel == RenderChannel::kClassification) {
    const bool classes = options.channel == RenderChannel::kClassification || HoldsAsprsClasses(cells);
    const std::vector<int32_t> shown = PresentLabels(cells);
    std::vector<std::pair<cv::Vec3b, std::string>> entries;
    for (size_t i = 0; i < shown.size(); ++i) {
      entries.emplace_back(classes ? AsprsClassColor(shown[i]) : LabelColor(shown[i]),
                           colored.legend_lines[i]);
    }
    legend = SwatchLegend(entries, size.height);
  } else if (options.channel == RenderChannel::kNormals) {
    legend = NormalsKey(std::min(size.height, 160));
  }
  if (legend.empty()) return colored;
  if (any_no_return) legend = StackLegends(legend, NoReturnKey(legend.cols, no_data_text));
  colored.image = BesideLegend(colored.image, legend);
  return colored;
}

}  // namespace

RenderResult RenderScan(const Scan& scan, const RenderOptions& options) {
  options.Check();
  CheckOption(!options.hillshade,
              "hillshade shades the orthographic views (top, front, side), not a ray grid");
  CheckScan(scan);
  return FinishPicture(scan, ColorCells(scan, options), cv::Size(scan.cols, scan.rows), options);
}

PictureResult RenderPicture(const Scan& scan, const RenderOptions& options,
                            const PictureLayoutOptions& layout_options) {
  options.Check();
  PictureLayout layout = LayOutPicture(scan, layout_options);
  const bool orthographic = TowardViewer(layout.view) != Eigen::Vector3d::Zero();
  if (options.hillshade && !orthographic) {
    throw OptionsError(
        fmt::format("hillshade shades the orthographic views (top, front, side), not the {} view",
                    ToString(layout.view)));
  }
  if (orthographic && options.channel == RenderChannel::kNormals && layout.cells.normal.empty()) {
    layout.cells.normal = OrthographicNormals(layout);
  }
  RenderResult colored = ColorCells(layout.cells, options);
  // Orthographic cells are the picture's pixels (no resampling), so the shading works on them directly.
  if (options.hillshade) Hillshade(layout, &colored.image);
  colored = FinishPicture(layout.cells, std::move(colored), layout.picture_size, options,
                          layout.view == PictureView::kGrid ? "no return" : "no point");
  return {std::move(colored.image), std::move(colored.scale), std::move(colored.legend_lines),
          std::move(layout)};
}

std::pair<double, double> IntensityFileRange(const Scan& scan) {
  // Metadata the scan's own reader wrote; anything else (edited by hand, not a number, an empty range) falls
  // back to the stored scale.
  auto number = [&](const char* key, double fallback) {
    const auto found = scan.source_metadata.find(key);
    if (found == scan.source_metadata.end()) return fallback;
    double value = 0;
    const auto [end, error] =
        std::from_chars(found->second.data(), found->second.data() + found->second.size(), value);
    return error == std::errc() && std::isfinite(value) && std::abs(value) <= 1e12 ? value : fallback;
  };
  const double low = number("intensity.file_minimum", 0.0), high = number("intensity.file_maximum", 1.0);
  return high > low ? std::pair{low, high} : std::pair{0.0, 1.0};
}

bool HoldsAsprsClasses(const Scan& scan) { return scan.source_metadata.count("las.point_format") > 0; }

bool HasFloatValues(RenderChannel channel) {
  return channel == RenderChannel::kRange || channel == RenderChannel::kElevation ||
         channel == RenderChannel::kIntensity || channel == RenderChannel::kNormals;
}

cv::Mat ChannelValues(const Scan& scan, RenderChannel channel) {
  CheckScan(scan);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat values;
  switch (channel) {
    case RenderChannel::kRange:
      values = scan.range.clone();
      break;
    case RenderChannel::kElevation:
      values = ElevationValues(scan);
      break;
    case RenderChannel::kIntensity:
      if (scan.intensity.empty()) {
        ThrowInputError(scan.name, "", "intensity", "the scan has no intensity channel");
      }
      values = scan.intensity.clone();
      break;
    case RenderChannel::kNormals:
      values = scan.normal.empty() ? EstimateGridNormals(scan) : scan.normal.clone();
      break;
    case RenderChannel::kRgb:
    case RenderChannel::kLabels:
    case RenderChannel::kClassification:
    case RenderChannel::kValid:
      throw OptionsError(fmt::format(
          "float pictures (.exr, .tif) hold range, elevation, intensity or normals, not {}; write {} as .png",
          ToString(channel), ToString(channel)));
  }
  values.setTo(cv::Scalar::all(nan), scan.valid == 0);
  return values;
}

ValuesResult RenderValues(const Scan& scan, RenderChannel channel,
                          const PictureLayoutOptions& layout_options) {
  PictureLayout layout = LayOutPicture(scan, layout_options);
  cv::Mat values = ResampleNearest(ChannelValues(layout.cells, channel), layout.picture_size);
  return {std::move(values), std::move(layout)};
}

cv::Mat NormalsKey(int height) {
  height = std::max(height, 100);
  const int text_rows = 30, radius = (height - text_rows - 8) / 2, width = std::max(2 * radius + 16, 110);
  cv::Mat key(height, width, CV_8UC3, cv::Scalar::all(255));
  const int centre_col = width / 2, centre_row = 4 + radius;
  for (int row = centre_row - radius; row <= centre_row + radius; ++row) {
    for (int col = centre_col - radius; col <= centre_col + radius; ++col) {
      const double x = static_cast<double>(col - centre_col) / radius;
      const double z = static_cast<double>(centre_row - row) / radius;
      if (x * x + z * z > 1.0) continue;
      // A normal facing the viewer: the scanner looks along +y, so the surfaces it sees face -y.
      const cv::Vec3f n(static_cast<float>(x), static_cast<float>(-std::sqrt(1.0 - x * x - z * z)),
                        static_cast<float>(z));
      key.at<cv::Vec3b>(row, col) = NormalColor(n);
    }
  }
  cv::putText(key, "x right, z up", cv::Point(6, height - text_rows + 10), cv::FONT_HERSHEY_SIMPLEX, 0.35,
              cv::Scalar::all(0), 1, cv::LINE_AA);
  cv::putText(key, "centre: facing scanner", cv::Point(6, height - text_rows + 24), cv::FONT_HERSHEY_SIMPLEX,
              0.35, cv::Scalar::all(0), 1, cv::LINE_AA);
  return key;
}

}  // namespace lidarshop
