// Touching neighbours (segment.h): where two convex bodies touch at the same range (two people shoulder to
// shoulder, a bin against a bin), their surfaces fold into each other along the contact and the scanner looks
// into a narrow crevice: along a grid line the range rises steeply to the contact from both sides (a range
// ridge with two steep flanks). Parts of one object meet at open creases (a seat and its back, a box on its
// plinth) where at least one side faces the scanner, so a ridge with two steep flanks separates neighbours.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Mean angle between neighbouring rays of the scan's grid, radians (0 without a grid).
double GridCellAngle(const Scan& scan) {
  const auto step = [](const std::vector<double>& angles) {
    return angles.size() < 2 ? 0.0 : std::abs(angles.back() - angles.front()) / (angles.size() - 1);
  };
  const double azimuth = step(scan.grid.azimuth_rad), elevation = step(scan.grid.elevation_rad);
  if (azimuth > 0 && elevation > 0) return 0.5 * (azimuth + elevation);
  return std::max(azimuth, elevation);
}

// Union-find over the cells of a box.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(n) {
    for (int i = 0; i < n; ++i) parent[i] = i;
  }
  int Find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void Join(int a, int b) { parent[Find(a)] = Find(b); }
};

}  // namespace

cv::Mat CreviceEdges(const Scan& scan, const cv::Rect& region, const WholeObjectOptions& options) {
  cv::Mat crevice = cv::Mat::zeros(region.size(), CV_8U);
  double cell_angle = GridCellAngle(scan);
  if (cell_angle <= 0) cell_angle = RayAngleAt(scan, scan.valid != 0);
  if (cell_angle <= 0) return crevice;
  const int k = options.crevice_baseline_cells;
  const double min_slope = std::tan(options.crevice_flank_deg * M_PI / 180.0);
  const cv::Rect image(0, 0, scan.cols, scan.rows);
  // Rise of the range from `far` to `near` per cell spacing (positive: the surface recedes towards `near`).
  const auto rise = [&](cv::Point near, cv::Point far) {
    if (!image.contains(far) || !scan.valid.at<uint8_t>(far)) return 0.0;
    const double range_m = scan.range.at<float>(near);
    return (range_m - scan.range.at<float>(far)) / (k * range_m * cell_angle);
  };
  for (int r = region.y; r < region.y + region.height; ++r) {
    for (int c = region.x; c < region.x + region.width; ++c) {
      const cv::Point a(c, r);
      if (!scan.valid.at<uint8_t>(a)) continue;
      // Bit 0: the edge to the right neighbour; bit 1: to the neighbour below.
      for (int axis = 0; axis < 2; ++axis) {
        const cv::Point d = axis == 0 ? cv::Point(1, 0) : cv::Point(0, 1);
        const cv::Point b = a + d;
        if (!region.contains(b) || !scan.valid.at<uint8_t>(b)) continue;
        if (rise(a, a - k * d) >= min_slope && rise(b, b + k * d) >= min_slope)
          crevice.at<uint8_t>(a - region.tl()) |= static_cast<uint8_t>(1 << axis);
      }
    }
  }
  return crevice;
}

cv::Mat TouchingNeighbours(const Scan& scan, const cv::Mat& mask, const cv::Mat& object_cells,
                           const WholeObjectOptions& options) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && mask.size() == cv::Size(scan.cols, scan.rows));
  LIDARSHOP_CHECK(object_cells.type() == CV_8U && object_cells.size() == mask.size());
  cv::Mat neighbours = cv::Mat::zeros(mask.size(), CV_8U);
  if (cv::countNonZero(mask) == 0) return neighbours;
  const cv::Rect box = cv::boundingRect(mask);
  const cv::Mat crevice = CreviceEdges(scan, box, options);
  // Parts of the mask: 4-connected without crossing a crevice.
  DisjointSets parts(box.area());
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      if (!mask.at<uint8_t>(r + box.y, c + box.x)) continue;
      const uint8_t bits = crevice.at<uint8_t>(r, c);
      if (c + 1 < box.width && mask.at<uint8_t>(r + box.y, c + 1 + box.x) && !(bits & 1))
        parts.Join(r * box.width + c, r * box.width + c + 1);
      if (r + 1 < box.height && mask.at<uint8_t>(r + 1 + box.y, c + box.x) && !(bits & 2))
        parts.Join(r * box.width + c, (r + 1) * box.width + c);
    }
  }
  std::vector<int> size(box.area(), 0);
  std::vector<uint8_t> stroked(box.area(), 0);
  int stroked_cells = 0;
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      if (!mask.at<uint8_t>(r + box.y, c + box.x)) continue;
      const int root = parts.Find(r * box.width + c);
      ++size[root];
      if (object_cells.at<uint8_t>(r + box.y, c + box.x)) stroked[root] = 1;
    }
  }
  for (int i = 0; i < box.area(); ++i)
    if (stroked[i]) stroked_cells += size[i];
  if (stroked_cells == 0) return neighbours;
  // A part the strokes do not touch that is as large as a fraction of the stroked parts is a neighbour; small
  // slivers cut off by noise stay with the object.
  const double min_cells = options.neighbour_min_fraction * stroked_cells;
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      if (!mask.at<uint8_t>(r + box.y, c + box.x)) continue;
      const int root = parts.Find(r * box.width + c);
      if (!stroked[root] && size[root] >= min_cells) neighbours.at<uint8_t>(r + box.y, c + box.x) = 255;
    }
  }
  return neighbours;
}

}  // namespace lidarshop
