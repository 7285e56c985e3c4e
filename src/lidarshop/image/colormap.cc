#include "lidarshop/image/colormap.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

std::vector<cv::Vec3b> BuildTable(int opencv_map) {
  cv::Mat ramp(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
  cv::Mat bgr, rgb;
  cv::applyColorMap(ramp, bgr, opencv_map);
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  std::vector<cv::Vec3b> table(256);
  for (int i = 0; i < 256; ++i) table[i] = rgb.at<cv::Vec3b>(0, i);
  return table;
}

std::string FormatTick(double value, double span) {
  const int decimals = span >= 50 ? 0 : span >= 5 ? 1 : span >= 0.5 ? 2 : 3;
  return fmt::format("{:.{}f}", value, decimals);
}

}  // namespace

const std::vector<cv::Vec3b>& ColorMapTable(ColorMap map) {
  static const std::vector<cv::Vec3b> viridis = BuildTable(cv::COLORMAP_VIRIDIS);
  static const std::vector<cv::Vec3b> turbo = BuildTable(cv::COLORMAP_TURBO);
  static const std::vector<cv::Vec3b> magma = BuildTable(cv::COLORMAP_MAGMA);
  static const std::vector<cv::Vec3b> gray = [] {
    std::vector<cv::Vec3b> table(256);
    for (int i = 0; i < 256; ++i) table[i] = cv::Vec3b(i, i, i);
    return table;
  }();
  switch (map) {
    case ColorMap::kViridis:
      return viridis;
    case ColorMap::kTurbo:
      return turbo;
    case ColorMap::kMagma:
      return magma;
    case ColorMap::kGray:
      return gray;
  }
  return viridis;
}

ColorScale AutoScale(const cv::Mat& values, const cv::Mat& mask, ColorMap map, const std::string& unit,
                     double low_fraction, double high_fraction) {
  LIDARSHOP_CHECK(values.type() == CV_32F);
  std::vector<float> samples;
  samples.reserve(values.total());
  for (int row = 0; row < values.rows; ++row) {
    const float* v = values.ptr<float>(row);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(row);
    for (int col = 0; col < values.cols; ++col) {
      if ((m == nullptr || m[col]) && std::isfinite(v[col])) samples.push_back(v[col]);
    }
  }
  ColorScale scale;
  scale.map = map;
  scale.unit = unit;
  if (samples.empty()) return scale;
  auto quantile = [&](double fraction) {
    const size_t index =
        std::min(samples.size() - 1, static_cast<size_t>(fraction * (samples.size() - 1) + 0.5));
    std::nth_element(samples.begin(), samples.begin() + index, samples.end());
    return static_cast<double>(samples[index]);
  };
  scale.min_value = quantile(low_fraction);
  scale.max_value = quantile(high_fraction);
  if (scale.max_value <= scale.min_value) scale.max_value = scale.min_value + 1e-6;
  return scale;
}

cv::Mat ApplyColorMap(const cv::Mat& values, const cv::Mat& mask, const ColorScale& scale,
                      const cv::Vec3b& invalid_color) {
  LIDARSHOP_CHECK(values.type() == CV_32F);
  LIDARSHOP_CHECK(mask.empty() || (mask.type() == CV_8U && mask.size() == values.size()));
  const std::vector<cv::Vec3b>& table = ColorMapTable(scale.map);
  const double span = scale.max_value - scale.min_value;
  const double factor = span > 0 ? 255.0 / span : 0.0;
  cv::Mat image(values.size(), CV_8UC3);
  for (int row = 0; row < values.rows; ++row) {
    const float* v = values.ptr<float>(row);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(row);
    cv::Vec3b* out = image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < values.cols; ++col) {
      if ((m != nullptr && !m[col]) || !std::isfinite(v[col])) {
        out[col] = invalid_color;
        continue;
      }
      const double level = std::clamp((v[col] - scale.min_value) * factor, 0.0, 255.0);
      out[col] = table[static_cast<int>(level + 0.5)];
    }
  }
  return image;
}

cv::Mat ColorScaleBar(const ColorScale& scale, int height) {
  height = std::max(height, 120);
  const int width = 110, bar_left = 8, bar_width = 22, margin = 12;
  cv::Mat legend(height, width, CV_8UC3, cv::Scalar::all(255));
  const std::vector<cv::Vec3b>& table = ColorMapTable(scale.map);
  const int top = margin, bottom = height - margin - 1;
  for (int y = top; y <= bottom; ++y) {
    const double t = static_cast<double>(bottom - y) / std::max(1, bottom - top);  // 1 at the top
    const cv::Vec3b color = table[static_cast<int>(std::round(t * 255))];
    for (int x = bar_left; x < bar_left + bar_width; ++x) legend.at<cv::Vec3b>(y, x) = color;
  }
  cv::rectangle(legend, cv::Point(bar_left - 1, top - 1), cv::Point(bar_left + bar_width, bottom + 1),
                cv::Scalar::all(0));
  const double span = scale.max_value - scale.min_value;
  const int ticks = height >= 200 ? 5 : 3;
  for (int i = 0; i < ticks; ++i) {
    const double t = static_cast<double>(i) / (ticks - 1);
    const int y = static_cast<int>(std::round(bottom - t * (bottom - top)));
    const double value = scale.min_value + t * span;
    cv::line(legend, cv::Point(bar_left + bar_width, y), cv::Point(bar_left + bar_width + 4, y),
             cv::Scalar::all(0));
    std::string text = FormatTick(value, span);
    if (i == ticks - 1 && !scale.unit.empty()) text += " " + scale.unit;
    cv::putText(legend, text, cv::Point(bar_left + bar_width + 7, y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.38,
                cv::Scalar::all(0), 1, cv::LINE_AA);
  }
  return legend;
}

cv::Vec3b LabelColor(int32_t label, const cv::Vec3b& negative_color) {
  if (label < 0) return negative_color;
  // Golden-ratio hue steps give neighbouring labels far-apart hues; saturation and value alternate a little.
  const double hue = std::fmod(0.1 + label * 0.6180339887498949, 1.0) * 180.0;
  const int saturation = label % 2 == 0 ? 200 : 160;
  const int value = label % 3 == 0 ? 250 : 210;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, saturation, value)), rgb;
  cv::cvtColor(hsv, rgb, cv::COLOR_HSV2RGB);
  return rgb.at<cv::Vec3b>(0, 0);
}

cv::Mat ColorLabels(const cv::Mat& labels, const cv::Mat& mask) {
  LIDARSHOP_CHECK(labels.type() == CV_32S);
  LIDARSHOP_CHECK(mask.empty() || (mask.type() == CV_8U && mask.size() == labels.size()));
  cv::Mat image(labels.size(), CV_8UC3, cv::Scalar::all(0));
  std::vector<std::pair<int32_t, cv::Vec3b>> cache;
  for (int row = 0; row < labels.rows; ++row) {
    const int32_t* l = labels.ptr<int32_t>(row);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(row);
    cv::Vec3b* out = image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < labels.cols; ++col) {
      if (m != nullptr && !m[col]) continue;
      auto found =
          std::find_if(cache.begin(), cache.end(), [&](const auto& entry) { return entry.first == l[col]; });
      if (found == cache.end()) {
        cache.emplace_back(l[col], LabelColor(l[col]));
        found = cache.end() - 1;
      }
      out[col] = found->second;
    }
  }
  return image;
}

cv::Mat SwatchLegend(const std::vector<std::pair<cv::Vec3b, std::string>>& entries, int height) {
  const int row_height = 18;
  const int needed = static_cast<int>(entries.size()) * row_height + 16;
  int width = 110;
  for (const auto& [color, text] : entries) {
    int baseline = 0;
    const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, &baseline);
    width = std::max(width, 28 + size.width + 8);
  }
  cv::Mat legend(std::max(height, needed), width, CV_8UC3, cv::Scalar::all(255));
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = 8 + static_cast<int>(i) * row_height;
    const cv::Vec3b color = entries[i].first;
    cv::rectangle(legend, cv::Rect(8, y, 14, 14), cv::Scalar(color[0], color[1], color[2]), cv::FILLED);
    cv::rectangle(legend, cv::Rect(8, y, 14, 14), cv::Scalar::all(0));
    cv::putText(legend, entries[i].second, cv::Point(28, y + 12), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar::all(0), 1, cv::LINE_AA);
  }
  return legend;
}

cv::Mat LabelLegend(const std::vector<int32_t>& labels, int height,
                    const std::map<int32_t, std::string>& names) {
  std::vector<std::pair<cv::Vec3b, std::string>> entries;
  for (const int32_t label : labels) {
    std::string text = label < 0 ? std::string("none") : fmt::format("label {}", label);
    const auto name = names.find(label);
    if (name != names.end() && !name->second.empty()) {
      text = label < 0 ? name->second : fmt::format("{}  {}", label, name->second);
    }
    entries.emplace_back(LabelColor(label), std::move(text));
  }
  return SwatchLegend(entries, height);
}

namespace {

struct AsprsClass {
  const char* name;
  cv::Vec3b color;  // RGB
};

// LAS 1.4 R15 table 17; codes 8 and 12 are "reserved" in 1.4 and had these meanings in LAS 1.1-1.3.
const AsprsClass kAsprsClasses[] = {
    {"never classified", {110, 110, 110}},   // 0
    {"unclassified", {150, 160, 178}},       // 1: slate grey, apart from the checker's neutral greys
    {"ground", {166, 112, 58}},              // 2
    {"low vegetation", {160, 215, 110}},     // 3
    {"medium vegetation", {80, 178, 72}},    // 4
    {"high vegetation", {22, 118, 48}},      // 5
    {"building", {228, 82, 52}},             // 6
    {"low noise", {255, 0, 255}},            // 7
    {"model key-point", {255, 222, 0}},      // 8
    {"water", {38, 100, 230}},               // 9
    {"rail", {140, 80, 160}},                // 10
    {"road surface", {60, 60, 60}},          // 11
    {"overlap", {240, 200, 120}},            // 12
    {"wire guard", {255, 255, 120}},         // 13
    {"wire conductor", {255, 196, 0}},       // 14
    {"transmission tower", {200, 120, 0}},   // 15
    {"wire connector", {255, 140, 200}},     // 16
    {"bridge deck", {120, 90, 200}},         // 17
    {"high noise", {200, 0, 200}},           // 18
    {"overhead structure", {0, 190, 200}},   // 19
    {"ignored ground", {200, 170, 130}},     // 20
    {"snow", {232, 244, 255}},               // 21
    {"temporal exclusion", {120, 120, 60}},  // 22
};
constexpr int32_t kAsprsClassCount = static_cast<int32_t>(std::size(kAsprsClasses));

}  // namespace

std::string AsprsClassName(int32_t code) {
  if (code >= 0 && code < kAsprsClassCount) return kAsprsClasses[code].name;
  return fmt::format("class {}", code);
}

cv::Vec3b AsprsClassColor(int32_t code) {
  if (code >= 0 && code < kAsprsClassCount) return kAsprsClasses[code].color;
  return LabelColor(code);  // user-defined classes (64-255) and others: distinct colours
}

cv::Mat ColorAsprsClasses(const cv::Mat& classes, const cv::Mat& mask) {
  LIDARSHOP_CHECK(classes.type() == CV_32S);
  LIDARSHOP_CHECK(mask.empty() || (mask.type() == CV_8U && mask.size() == classes.size()));
  cv::Mat image(classes.size(), CV_8UC3, cv::Scalar::all(0));
  for (int row = 0; row < classes.rows; ++row) {
    const int32_t* c = classes.ptr<int32_t>(row);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(row);
    cv::Vec3b* out = image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < classes.cols; ++col) {
      if (m == nullptr || m[col]) out[col] = AsprsClassColor(c[col]);
    }
  }
  return image;
}

void PaintNoReturn(cv::Mat* image, const cv::Mat& valid) {
  LIDARSHOP_CHECK(image->type() == CV_8UC3 && valid.type() == CV_8U && valid.size() == image->size());
  for (int row = 0; row < image->rows; ++row) {
    const uint8_t* v = valid.ptr<uint8_t>(row);
    cv::Vec3b* out = image->ptr<cv::Vec3b>(row);
    for (int col = 0; col < image->cols; ++col) {
      if (!v[col]) out[col] = NoReturnColor(row, col);
    }
  }
}

cv::Mat NoReturnKey(int width, const std::string& text) {
  cv::Mat key(26, std::max(width, 110), CV_8UC3, cv::Scalar::all(255));
  for (int row = 6; row < 22; ++row) {
    for (int col = 8; col < 24; ++col) key.at<cv::Vec3b>(row, col) = NoReturnColor(row - 6, col - 8);
  }
  cv::rectangle(key, cv::Rect(7, 5, 18, 18), cv::Scalar::all(0));
  cv::putText(key, text, cv::Point(30, 18), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(0), 1,
              cv::LINE_AA);
  return key;
}

cv::Mat StackLegends(const cv::Mat& top, const cv::Mat& bottom) {
  LIDARSHOP_CHECK(top.type() == CV_8UC3 && bottom.type() == CV_8UC3);
  cv::Mat combined(top.rows + bottom.rows, std::max(top.cols, bottom.cols), CV_8UC3, cv::Scalar::all(255));
  top.copyTo(combined(cv::Rect(0, 0, top.cols, top.rows)));
  bottom.copyTo(combined(cv::Rect(0, top.rows, bottom.cols, bottom.rows)));
  return combined;
}

cv::Mat BesideLegend(const cv::Mat& image, const cv::Mat& legend) {
  LIDARSHOP_CHECK(image.type() == CV_8UC3 && legend.type() == CV_8UC3);
  const int height = std::max(image.rows, legend.rows);
  cv::Mat combined(height, image.cols + legend.cols, CV_8UC3, cv::Scalar::all(255));
  image.copyTo(combined(cv::Rect(0, 0, image.cols, image.rows)));
  legend.copyTo(combined(cv::Rect(image.cols, 0, legend.cols, legend.rows)));
  return combined;
}

}  // namespace lidarshop
