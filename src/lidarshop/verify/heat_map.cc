// Pictures of sweep heat maps (sweep.h: RenderHeatMap, HeatMapLayoutOf).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/verify/sweep.h"

namespace lidarshop {
namespace {

constexpr int kMargin = 10, kLeft = 58, kTop = 36, kBottom = 64, kBarW = 24, kBarGap = 16, kLabelW = 50;
const cv::Scalar kBlack(0, 0, 0), kWhite(255, 255, 255);
const cv::Scalar kNoPairBgr(150, 150, 150);   // evaluated, no comparable pair
const cv::Scalar kSkippedBgr(236, 236, 236);  // not verified: the coarse-to-fine bound says it cannot pass
constexpr double kPointShade = 0.4;           // how much a cell pixel with scene points under it darkens

// A tick step of 1, 2 or 5 × 10^k metres giving at most `max_ticks` ticks over `span_m`.
double TickStep(double span_m, int max_ticks) {
  for (double decade = 0.01; decade < 1e7; decade *= 10) {
    for (double mantissa : {1.0, 2.0, 5.0}) {
      if (span_m / (mantissa * decade) <= max_ticks) return mantissa * decade;
    }
  }
  return 1e7;
}

std::string TickLabel(double value_m, double step_m) {
  if (std::abs(value_m) < 1e-9 * step_m) value_m = 0;  // no "-0"
  return step_m >= 1 ? fmt::format("{:.0f}", value_m) : fmt::format("{:.1f}", value_m);
}

void Text(cv::Mat& canvas, const std::string& text, cv::Point at, double scale = 0.4) {
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, kBlack, 1, cv::LINE_AA);
}
int TextWidth(const std::string& text, double scale = 0.4) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width;
}

}  // namespace

cv::Point2d HeatMapLayout::PixelOf(double x_m, double y_m) const {
  return {map.x + ((x_m - x0_m) / step_m + 0.5) * cell_px, map.y + ((y1_m - y_m) / step_m + 0.5) * cell_px};
}

HeatMapLayout HeatMapLayoutOf(const cv::Mat& values, const SweepResult& sweep, int cell_px) {
  const int rows = values.rows, cols = values.cols;
  HeatMapLayout layout;
  layout.cell_px = cell_px > 0 ? cell_px : std::clamp(600 / std::max(1, std::max(rows, cols)), 1, 40);
  layout.map = cv::Rect(kLeft, kTop, cols * layout.cell_px, rows * layout.cell_px);
  if (!sweep.xs_m.empty() && !sweep.ys_m.empty()) {
    layout.x0_m = sweep.xs_m.front();
    layout.y1_m = sweep.ys_m.back();
    if (sweep.xs_m.size() > 1) {
      layout.step_m = sweep.xs_m[1] - sweep.xs_m[0];
    } else if (sweep.ys_m.size() > 1) {
      layout.step_m = sweep.ys_m[1] - sweep.ys_m[0];
    }
  }
  return layout;
}

cv::Mat RenderHeatMap(const cv::Mat& values, const SweepResult& sweep, const std::string& title,
                      double threshold, int cell_px) {
  LIDARSHOP_CHECK(values.type() == CV_32F);
  const int rows = values.rows, cols = values.cols;
  const HeatMapLayout layout = HeatMapLayoutOf(values, sweep, cell_px);
  cell_px = layout.cell_px;
  const cv::Rect map = layout.map;
  const int bar_h = std::max(map.height, 120);
  const int width = map.x + map.width + kBarGap + kBarW + kLabelW + kMargin;
  const int height = kTop + bar_h + kBottom;
  cv::Mat canvas(height, width, CV_8UC3, kWhite);
  const bool has_evaluated = sweep.evaluated_map.rows == rows && sweep.evaluated_map.cols == cols &&
                             sweep.evaluated_map.type() == CV_8U;

  // Cells: 8-bit levels through viridis (OpenCV returns BGR; the canvas is BGR until the end).
  cv::Mat levels(rows, cols, CV_8U), nan_mask(rows, cols, CV_8U), skipped_mask(rows, cols, CV_8U);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float v = values.at<float>(r, c);
      const bool skipped = has_evaluated && sweep.evaluated_map.at<uint8_t>(r, c) == 0;
      skipped_mask.at<uint8_t>(r, c) = skipped ? 255 : 0;
      nan_mask.at<uint8_t>(r, c) = std::isnan(v) && !skipped ? 255 : 0;
      levels.at<uint8_t>(r, c) =
          std::isnan(v) ? 0 : static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255));
    }
  }
  cv::Mat colored;
  cv::applyColorMap(levels, colored, cv::COLORMAP_VIRIDIS);
  colored.setTo(kNoPairBgr, nan_mask);
  colored.setTo(kSkippedBgr, skipped_mask);
  cv::Mat scaled;
  cv::resize(colored, scaled, map.size(), 0, 0, cv::INTER_NEAREST);

  // The scene points underneath: every pixel with a point darkens (faintly, so the values stay readable).
  cv::Mat has_point = cv::Mat::zeros(map.size(), CV_8U);
  for (const Eigen::Vector2f& p : sweep.scene_xy_m) {
    const cv::Point2d px = layout.PixelOf(p.x(), p.y());
    const int x = static_cast<int>(std::floor(px.x)) - map.x, y = static_cast<int>(std::floor(px.y)) - map.y;
    if (x >= 0 && x < map.width && y >= 0 && y < map.height) has_point.at<uint8_t>(y, x) = 1;
  }
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      if (has_point.at<uint8_t>(y, x) == 0) continue;
      cv::Vec3b& bgr = scaled.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) bgr[k] = static_cast<uint8_t>(std::lround(bgr[k] * (1.0 - kPointShade)));
    }
  }
  scaled.copyTo(canvas(map));
  cv::rectangle(canvas, cv::Rect(map.x - 1, map.y - 1, map.width + 2, map.height + 2), kBlack, 1);

  // Axes in metres: ticks at multiples of a round step inside the map's extent (cell edges).
  if (!sweep.xs_m.empty() && !sweep.ys_m.empty()) {
    const double half = 0.5 * layout.step_m;
    const double x_lo = sweep.xs_m.front() - half, x_hi = sweep.xs_m.back() + half;
    const double y_lo = sweep.ys_m.front() - half, y_hi = sweep.ys_m.back() + half;
    const double x_step = TickStep(x_hi - x_lo, std::max(2, map.width / 60));
    const double y_step = TickStep(y_hi - y_lo, std::max(2, map.height / 40));
    for (double x = std::ceil(x_lo / x_step) * x_step; x <= x_hi + 1e-9; x += x_step) {
      const int px = static_cast<int>(std::lround(layout.PixelOf(x, 0).x - 0.5 * cell_px));
      cv::line(canvas, cv::Point(px, map.y + map.height), cv::Point(px, map.y + map.height + 5), kBlack);
      const std::string label = TickLabel(x, x_step);
      Text(canvas, label, cv::Point(px - TextWidth(label) / 2, map.y + map.height + 18));
    }
    for (double y = std::ceil(y_lo / y_step) * y_step; y <= y_hi + 1e-9; y += y_step) {
      const int py = static_cast<int>(std::lround(layout.PixelOf(0, y).y - 0.5 * cell_px));
      cv::line(canvas, cv::Point(map.x - 6, py), cv::Point(map.x - 1, py), kBlack);
      const std::string label = TickLabel(y, y_step);
      Text(canvas, label, cv::Point(map.x - 9 - TextWidth(label), py + 4));
    }
    Text(canvas, "x (m)", cv::Point(map.x + map.width - TextWidth("x (m)"), map.y + map.height + 34));
    Text(canvas, "y (m)", cv::Point(4, map.y - 8));
  }

  // Detections as rings.
  for (const Detection& d : sweep.detections) {
    const cv::Point2d px = layout.PixelOf(d.x_m, d.y_m);
    const cv::Point centre(static_cast<int>(px.x), static_cast<int>(px.y));
    cv::circle(canvas, centre, std::max(6, 2 * cell_px), kWhite, 2, cv::LINE_AA);
    cv::circle(canvas, centre, std::max(6, 2 * cell_px) + 2, kBlack, 1, cv::LINE_AA);
  }

  // Scanners: a magenta disc with a black rim where they stand inside the map (their x, y otherwise noted).
  std::string outside;
  for (const Eigen::Vector2d& scanner : sweep.scanner_xy_m) {
    const cv::Point2d px = layout.PixelOf(scanner.x(), scanner.y());
    const cv::Point centre(static_cast<int>(std::floor(px.x)), static_cast<int>(std::floor(px.y)));
    if (!map.contains(centre)) {
      outside += fmt::format(" ({:.1f}, {:.1f})", scanner.x(), scanner.y());
      continue;
    }
    const int radius = std::max(5, cell_px / 2);
    cv::circle(canvas, centre, radius + 1, kBlack, cv::FILLED, cv::LINE_8);
    const cv::Vec3b rgb = kHeatMapScannerRgb;
    cv::circle(canvas, centre, radius, cv::Scalar(rgb[2], rgb[1], rgb[0]), cv::FILLED, cv::LINE_8);
  }

  // Colour scale.
  const int bar_x = map.x + map.width + kBarGap;
  for (int y = 0; y < bar_h; ++y) {
    cv::Mat level(1, 1, CV_8U,
                  cv::Scalar(static_cast<int>(std::lround(255.0 * (bar_h - 1 - y) / (bar_h - 1)))));
    cv::Mat color;
    cv::applyColorMap(level, color, cv::COLORMAP_VIRIDIS);
    const cv::Vec3b bgr = color.at<cv::Vec3b>(0, 0);
    cv::line(canvas, cv::Point(bar_x, kTop + y), cv::Point(bar_x + kBarW - 1, kTop + y),
             cv::Scalar(bgr[0], bgr[1], bgr[2]));
  }
  cv::rectangle(canvas, cv::Rect(bar_x, kTop, kBarW, bar_h), kBlack, 1);
  for (int tick = 0; tick <= 4; ++tick) {
    const int y = kTop + static_cast<int>(std::lround((bar_h - 1) * (1.0 - tick / 4.0)));
    cv::line(canvas, cv::Point(bar_x + kBarW, y), cv::Point(bar_x + kBarW + 4, y), kBlack);
    Text(canvas, fmt::format("{:.2f}", tick / 4.0), cv::Point(bar_x + kBarW + 6, y + 4), 0.38);
  }
  if (threshold >= 0 && threshold <= 1) {
    const int y = kTop + static_cast<int>(std::lround((bar_h - 1) * (1.0 - threshold)));
    cv::line(canvas, cv::Point(bar_x - 4, y), cv::Point(bar_x + kBarW + 4, y), cv::Scalar(0, 0, 255), 2);
  }
  cv::putText(canvas, title, cv::Point(kLeft, 24), cv::FONT_HERSHEY_SIMPLEX, 0.55, kBlack, 1, cv::LINE_AA);
  std::string legend = "magenta = scanner, dark = scene points, grey = no comparable pair";
  if (has_evaluated && cv::countNonZero(skipped_mask) > 0) legend += ", pale = not verified (cannot pass)";
  if (!outside.empty()) legend += "; scanner outside at" + outside;
  Text(canvas, legend, cv::Point(4, map.y + bar_h + 54), 0.36);
  cv::Mat rgb;
  cv::cvtColor(canvas, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace lidarshop
