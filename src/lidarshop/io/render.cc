#include "lidarshop/io/render.h"

#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

RenderResult RenderScan(const Scan& scan, const RenderOptions& options) {
  options.Check();
  CheckScan(scan);
  RenderResult result;
  auto metric = [&](const cv::Mat& values, ColorMap default_map, const std::string& unit, bool unit_range) {
    const ColorMap map = options.color_map.value_or(default_map);
    ColorScale scale =
        unit_range ? ColorScale{0.0, 1.0, map, unit} : AutoScale(values, scan.valid, map, unit);
    if (!std::isnan(options.min_value)) scale.min_value = options.min_value;
    if (!std::isnan(options.max_value)) scale.max_value = options.max_value;
    if (scale.max_value <= scale.min_value) scale.max_value = scale.min_value + 1e-6;
    result.image = ApplyColorMap(values, scan.valid, scale);
    result.scale = scale;
  };
  switch (options.channel) {
    case RenderChannel::kRange:
      metric(scan.range, ColorMap::kViridis, "m", false);
      break;
    case RenderChannel::kIntensity: {
      if (!scan.has_intensity()) {
        // Name what there is instead (leaving out range, valid and direction, which every scan has).
        std::vector<std::string> present;
        for (const std::string& name : ChannelNames(scan)) {
          if (name != "range" && name != "valid" && name != "direction") present.push_back(name);
        }
        throw InputError(fmt::format("{} has no intensity channel; it has: {}",
                                     scan.name.empty() ? "the scan" : scan.name, fmt::join(present, ", ")));
      }
      double low = 0, high = 0;
      cv::minMaxLoc(scan.intensity, &low, &high, nullptr, nullptr, scan.valid);
      // PTX intensities are in [0, 1]; other scales (integer counts) get automatic limits.
      metric(scan.intensity, ColorMap::kGray, "", low >= 0 && high <= 1);
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
          cv::Vec3b& out = result.image.at<cv::Vec3b>(row, col);
          for (int k = 0; k < 3; ++k) out[k] = cv::saturate_cast<uint8_t>((n[k] + 1.0f) * 127.5f);
        }
      }
      break;
    }
    case RenderChannel::kLabels:
      if (scan.label.empty()) ThrowInputError(scan.name, "", "labels", "the scan has no label channel");
      result.image = ColorLabels(scan.label, scan.valid);
      break;
    case RenderChannel::kValid:
      result.image = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar::all(0));
      result.image.setTo(cv::Scalar::all(255), scan.valid);
      break;
  }
  if (options.legend) {
    if (result.scale) {
      result.image = BesideLegend(result.image, ColorScaleBar(*result.scale, scan.rows));
    } else if (options.channel == RenderChannel::kLabels) {
      std::set<int32_t> present;
      for (int row = 0; row < scan.rows; ++row) {
        for (int col = 0; col < scan.cols; ++col) {
          if (scan.valid.at<uint8_t>(row, col)) present.insert(scan.label.at<int32_t>(row, col));
        }
      }
      std::vector<int32_t> shown(present.begin(), present.end());
      if (shown.size() > 40) shown.resize(40);  // a legend, not a catalogue
      result.image = BesideLegend(result.image, LabelLegend(shown, scan.rows));
    }
  }
  return result;
}

}  // namespace lidarshop
