// Colours of the segmentation overlay (segment.h): a tint that stands out from the scan's own colours, and
// strokes thick enough to see on a picture shown smaller than the scan.
#include <algorithm>
#include <array>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/render/render_layout.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Saturated colours first (they read as "selection"), then white; green and red are the strokes' colours.
constexpr std::array<std::array<uint8_t, 3>, 6> kOverlayCandidates = {{
    {255, 220, 0},    // yellow (the tint on most outdoor scenes: grass, asphalt, facades)
    {255, 0, 255},    // magenta
    {0, 220, 255},    // cyan
    {255, 128, 0},    // orange
    {60, 90, 255},    // blue
    {255, 255, 255},  // white
}};

cv::Vec3f Lab(const cv::Vec3b& rgb) {
  cv::Mat pixel(1, 1, CV_32FC3, cv::Scalar(rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0)), lab;
  cv::cvtColor(pixel, lab, cv::COLOR_RGB2Lab);
  return lab.at<cv::Vec3f>(0, 0);
}

}  // namespace

cv::Vec3b ContrastingOverlayColor(const cv::Mat& picture_rgb, const cv::Mat& region) {
  LIDARSHOP_CHECK(picture_rgb.type() == CV_8UC3);
  LIDARSHOP_CHECK(region.empty() || (region.size() == picture_rgb.size() && region.type() == CV_8U));
  // Up to ~20k sampled pixels on a fixed stride: deterministic, and enough for a robust low quantile.
  std::vector<cv::Point> cells;
  if (region.empty() || cv::countNonZero(region) == 0) {
    for (int r = 0; r < picture_rgb.rows; ++r)
      for (int c = 0; c < picture_rgb.cols; ++c) cells.emplace_back(c, r);
  } else {
    cv::findNonZero(region, cells);
  }
  const size_t stride = std::max<size_t>(1, cells.size() / 20000);
  cv::Mat samples(static_cast<int>((cells.size() + stride - 1) / stride), 1, CV_8UC3), samples_lab;
  for (size_t i = 0, k = 0; i < cells.size(); i += stride, ++k)
    samples.at<cv::Vec3b>(static_cast<int>(k)) = picture_rgb.at<cv::Vec3b>(cells[i]);
  samples.convertTo(samples, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(samples, samples_lab, cv::COLOR_RGB2Lab);

  // Distances are taken at the 10th percentile (a colour distinct from nearly all of the object and its
  // surroundings, not merely from their mean). The first candidate at least kDistinct away wins, so the tint
  // stays the familiar yellow wherever yellow is visible; otherwise the farthest one.
  constexpr float kDistinct = 40.0f;  // CIELAB units: about twice a "clearly different colour"
  cv::Vec3b best(kOverlayCandidates[0][0], kOverlayCandidates[0][1], kOverlayCandidates[0][2]);
  float best_distance = -1;
  std::vector<float> distances(static_cast<size_t>(samples_lab.rows));
  for (const auto& candidate : kOverlayCandidates) {
    const cv::Vec3b rgb(candidate[0], candidate[1], candidate[2]);
    const cv::Vec3f lab = Lab(rgb);
    for (int i = 0; i < samples_lab.rows; ++i)
      distances[static_cast<size_t>(i)] = static_cast<float>(cv::norm(samples_lab.at<cv::Vec3f>(i) - lab));
    auto quantile = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 10);
    std::nth_element(distances.begin(), quantile, distances.end());
    if (*quantile >= kDistinct) return rgb;
    if (*quantile > best_distance) {
      best_distance = *quantile;
      best = rgb;
    }
  }
  return best;
}

int OverlayStrokeRadius(cv::Size picture_size) {
  // One cell on scans up to ~800 cells across, growing so a stroke stays ~0.25 % of the picture wide.
  return std::max(1, std::max(picture_size.width, picture_size.height) / 400);
}

cv::Mat OverlayOnPicture(const Scan& scan, const cv::Mat& mask, const PaintedStrokes& strokes) {
  if (strokes.mapping && strokes.mapping->view == PictureView::kGrid) {
    return SegmentOverlayPicture(scan, mask, strokes.cells, strokes.mapping->picture_size, strokes.picture);
  }
  if (IsUnorganized(scan)) return SegmentOverlay(scan, mask, strokes.cells);
  return SegmentOverlayPicture(scan, mask, strokes.cells, LayOutPicture(scan, {}).picture_size);
}

}  // namespace lidarshop
