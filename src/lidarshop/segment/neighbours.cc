// Touching neighbours (segment.h): where two convex bodies touch at the same range (two people shoulder to
// shoulder, a bin against a bin), their surfaces fold into each other along the contact and the scanner looks
// into a narrow crevice: along a grid line the range rises steeply to the contact from both sides (a range
// ridge with two steep flanks). Parts of one object meet at open creases (a seat and its back, a box on its
// plinth) where at least one side faces the scanner, so a ridge with two steep flanks separates neighbours.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Angle between neighbouring rays of the scan's grid along its columns (azimuth) and rows (elevation), radians;
// without a grid, the angle measured between the scan's points for both.
cv::Vec2d CellAngles(const Scan& scan) {
  const auto step = [](const std::vector<double>& angles) {
    return angles.size() < 2 ? 0.0 : std::abs(angles.back() - angles.front()) / (angles.size() - 1);
  };
  const double azimuth = step(scan.grid.azimuth_rad), elevation = step(scan.grid.elevation_rad);
  if (azimuth > 0 && elevation > 0) return {azimuth, elevation};
  const double measured = RayAngleAt(scan, scan.valid != 0);
  return {azimuth > 0 ? azimuth : measured, elevation > 0 ? elevation : measured};
}

}  // namespace

cv::Mat CreviceEdges(const Scan& scan, const cv::Rect& region, const WholeObjectOptions& options) {
  cv::Mat crevice = cv::Mat::zeros(region.size(), CV_8U);
  const cv::Vec2d cell_angle = CellAngles(scan);
  if (cell_angle[0] <= 0 || cell_angle[1] <= 0) return crevice;
  const int k = options.crevice_baseline_cells;
  const double min_slope = std::tan(options.crevice_flank_deg * M_PI / 180.0);
  const cv::Rect image(0, 0, scan.cols, scan.rows);
  // Rise of the range from `far` to `near` per cell spacing along `axis` (positive: the surface recedes towards
  // `near`).
  const auto rise = [&](cv::Point near, cv::Point far, int axis) {
    if (!image.contains(far) || !scan.valid.at<uint8_t>(far)) return 0.0;
    const double range_m = scan.range.at<float>(near);
    return (range_m - scan.range.at<float>(far)) / (k * range_m * cell_angle[axis]);
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
        if (rise(a, a - k * d, axis) >= min_slope && rise(b, b + k * d, axis) >= min_slope)
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
  // The cells on either side of a crevice, the line closed over single missed cells along it (a crevice seen in
  // noise wanders by a cell from row to row and misses a row now and then; cut along the edges alone, the two
  // sides would still meet through such steps and gaps).
  cv::Mat across_rows = cv::Mat::zeros(box.size(), CV_8U), across_cols = across_rows.clone();
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      const uint8_t bits = crevice.at<uint8_t>(r, c);
      if (bits & 1) across_rows.at<uint8_t>(r, c) = across_rows.at<uint8_t>(r, c + 1) = 255;
      if (bits & 2) across_cols.at<uint8_t>(r, c) = across_cols.at<uint8_t>(r + 1, c) = 255;
    }
  }
  cv::morphologyEx(across_rows, across_rows, cv::MORPH_CLOSE, cv::Mat::ones(3, 1, CV_8U));
  cv::morphologyEx(across_cols, across_cols, cv::MORPH_CLOSE, cv::Mat::ones(1, 3, CV_8U));
  const cv::Mat in_mask = mask(box) != 0;
  const cv::Mat on_crevice = (across_rows | across_cols) & in_mask;
  // Parts: 4-connected components of the mask off the crevices.
  cv::Mat part;
  const int parts = cv::connectedComponents(in_mask & ~on_crevice, part, 4, CV_32S);
  // Crevice cells go to the part next to them closest in range, a layer at a time.
  for (bool changed = true; changed;) {
    changed = false;
    cv::Mat next = part.clone();
    for (int r = 0; r < box.height; ++r) {
      for (int c = 0; c < box.width; ++c) {
        if (!on_crevice.at<uint8_t>(r, c) || part.at<int32_t>(r, c) != 0) continue;
        const float range_m = scan.range.at<float>(r + box.y, c + box.x);
        float best = std::numeric_limits<float>::infinity();
        for (const cv::Point d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
          const cv::Point q(c + d.x, r + d.y);
          if (q.x < 0 || q.y < 0 || q.x >= box.width || q.y >= box.height || part.at<int32_t>(q) == 0)
            continue;
          const float gap = std::abs(scan.range.at<float>(q + box.tl()) - range_m);
          if (gap < best) {
            best = gap;
            next.at<int32_t>(r, c) = part.at<int32_t>(q);
            changed = true;
          }
        }
      }
    }
    part = next;
  }
  std::vector<int> size(parts, 0);
  std::vector<uint8_t> stroked(parts, 0);
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      const int label = part.at<int32_t>(r, c);
      if (label == 0 || !in_mask.at<uint8_t>(r, c)) continue;
      ++size[label];
      if (object_cells.at<uint8_t>(r + box.y, c + box.x)) stroked[label] = 1;
    }
  }
  int stroked_cells = 0;
  for (int label = 1; label < parts; ++label)
    if (stroked[label]) stroked_cells += size[label];
  if (stroked_cells == 0) return neighbours;
  // A part the strokes do not touch that is as large as a fraction of the stroked parts is a neighbour. Smaller
  // parts (a head on a torso, slivers cut off by noise) go with what they touch: the object first, else a
  // neighbour; a part that touches neither stays with the object.
  enum Side : uint8_t { kUndecided, kObject, kNeighbour };
  std::vector<Side> side(parts, kUndecided);
  const double min_cells = options.neighbour_min_fraction * stroked_cells;
  for (int label = 1; label < parts; ++label)
    side[label] = stroked[label] ? kObject : size[label] >= min_cells ? kNeighbour : kUndecided;
  std::vector<std::pair<int, int>> touching;
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      const int label = part.at<int32_t>(r, c);
      if (label == 0) continue;
      if (c + 1 < box.width && part.at<int32_t>(r, c + 1) != 0 && part.at<int32_t>(r, c + 1) != label)
        touching.emplace_back(label, part.at<int32_t>(r, c + 1));
      if (r + 1 < box.height && part.at<int32_t>(r + 1, c) != 0 && part.at<int32_t>(r + 1, c) != label)
        touching.emplace_back(label, part.at<int32_t>(r + 1, c));
    }
  }
  for (const Side spread : {kObject, kNeighbour}) {
    for (bool changed = true; changed;) {
      changed = false;
      for (const auto& [a, b] : touching) {
        for (const auto& [from, to] : {std::pair(a, b), std::pair(b, a)}) {
          if (side[from] == spread && side[to] == kUndecided) {
            side[to] = spread;
            changed = true;
          }
        }
      }
    }
  }
  for (int r = 0; r < box.height; ++r) {
    for (int c = 0; c < box.width; ++c) {
      const int label = part.at<int32_t>(r, c);
      if (label != 0 && in_mask.at<uint8_t>(r, c) && side[label] == kNeighbour)
        neighbours.at<uint8_t>(r + box.y, c + box.x) = 255;
    }
  }
  return neighbours;
}

}  // namespace lidarshop
