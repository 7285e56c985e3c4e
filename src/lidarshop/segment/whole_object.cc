// Whole-object growth (segment.h): parts of another colour that the colour cut leaves out (a mailbox's post,
// a van's wheels, a sign's flag) are joined through depth- and orientation-continuous grid edges; the support
// surface (ground, table, wall) meets the object at a crease and is not crossed.
#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Mean angle between neighbouring cells (radians): the scale of what "continuous in depth" means here.
double MeanCellAngle(const Scan& scan) {
  const auto step = [](const std::vector<double>& angles) {
    return angles.size() < 2 ? 0.0 : std::abs(angles.back() - angles.front()) / (angles.size() - 1);
  };
  const double azimuth = step(scan.grid.azimuth_rad), elevation = step(scan.grid.elevation_rad);
  if (azimuth > 0 && elevation > 0) return 0.5 * (azimuth + elevation);
  return std::max(azimuth, elevation);
}

// The same scan restricted to `rect` (channels share the buffers).
Scan CropView(const Scan& scan, const cv::Rect& rect) {
  Scan view;
  view.rows = rect.height;
  view.cols = rect.width;
  view.valid = scan.valid(rect);
  view.point = scan.point(rect);
  view.range = scan.range(rect);
  return view;
}

// Cells of `cells_mask` (all inside `box`, its bounding box) whose point lies within distance_m of the plane.
int CountOnPlane(const Scan& scan, const cv::Mat& cells_mask, const cv::Rect& box, const PlaneFit& plane,
                 double distance_m) {
  int count = 0;
  for (int r = box.y; r < box.y + box.height; ++r) {
    const uint8_t* in = cells_mask.ptr<uint8_t>(r);
    for (int c = box.x; c < box.x + box.width; ++c) {
      if (!in[c] || !scan.valid.at<uint8_t>(r, c)) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(r, c);
      count += std::abs(plane.Distance(Eigen::Vector3f(p[0], p[1], p[2]))) <= distance_m;
    }
  }
  return count;
}

// Cells on the surfaces the object stands on or against: planes found by RANSAC among the cells with a return
// in a band around the object, kept when a quarter of their band cells lie outside the object's bounding box
// (a face of a missed part lies within it; the ground, a table or a wall runs beyond it).
cv::Mat SupportCells(const Scan& scan, const cv::Mat& mask, const cv::Rect& region, const cv::Mat& normal,
                     const WholeObjectOptions& options) {
  cv::Mat band;
  cv::dilate(mask, band, cv::Mat(), cv::Point(-1, -1), options.support_band_cells);
  band &= ~mask;
  band &= scan.valid != 0;
  PointCloud cloud;
  std::vector<cv::Point> cells;
  cv::findNonZero(band(region), cells);
  cv::Mat support = cv::Mat::zeros(mask.size(), CV_8U);
  if (cells.size() < 50) return support;
  for (cv::Point& cell : cells) {
    cell += region.tl();
    const cv::Vec3f& p = scan.point.at<cv::Vec3f>(cell);
    cloud.points.emplace_back(p[0], p[1], p[2]);
  }
  RansacPlaneOptions ransac;
  ransac.distance_threshold_m = options.support_distance_m;
  ransac.max_planes = 3;
  ransac.min_inliers = static_cast<int>(cells.size() / 5);
  const cv::Rect box = cv::boundingRect(mask);
  const int object_cells = cv::countNonZero(mask);
  const float cos_max = static_cast<float>(std::cos(options.max_crease_deg * M_PI / 180.0));
  for (const PlaneFit& plane : DetectPlanesRansac(cloud, ransac)) {
    size_t outside_box = 0;
    for (uint32_t i : plane.inliers) outside_box += !box.contains(cells[i]);
    if (4 * outside_box < plane.inliers.size()) continue;
    // A plane through much of the cut itself is a face of the object (its other half in another colour).
    if (5 * CountOnPlane(scan, mask, box, plane, options.support_distance_m) > object_cells) continue;
    const cv::Vec3f plane_normal(static_cast<float>(plane.normal.x()), static_cast<float>(plane.normal.y()),
                                 static_cast<float>(plane.normal.z()));
    // Every cell of the region on that plane and facing its way, not only the band's.
    for (int r = region.y; r < region.y + region.height; ++r) {
      for (int c = region.x; c < region.x + region.width; ++c) {
        if (!scan.valid.at<uint8_t>(r, c) || mask.at<uint8_t>(r, c)) continue;
        const cv::Vec3f& p = scan.point.at<cv::Vec3f>(r, c);
        if (std::abs(plane.Distance(Eigen::Vector3f(p[0], p[1], p[2]))) > options.support_distance_m)
          continue;
        const cv::Vec3f n = normal.at<cv::Vec3f>(r - region.y, c - region.x);
        if (std::abs(n.dot(plane_normal)) >= cos_max) support.at<uint8_t>(r, c) = 255;
      }
    }
  }
  return support;
}

}  // namespace

cv::Mat GrowWholeObject(const Scan& scan, const cv::Mat& mask, const cv::Mat& barrier,
                        const WholeObjectOptions& options) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && mask.size() == cv::Size(scan.cols, scan.rows));
  LIDARSHOP_CHECK(barrier.empty() || (barrier.type() == CV_8U && barrier.size() == mask.size()));
  const int object_cells = cv::countNonZero(mask);
  if (object_cells == 0) return mask.clone();
  // Work on the object's box grown by as much again on every side: growth beyond it is a leak anyway.
  const cv::Rect box = cv::boundingRect(mask);
  const int margin = std::max(box.width, box.height);
  const cv::Rect region =
      cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
      cv::Rect(0, 0, scan.cols, scan.rows);
  const double cell_angle = MeanCellAngle(scan);
  // Normals from the window's cells near the centre only: a window across a depth edge would tilt the
  // normals of the background cells along the object's outline, and growth would crawl along that ring.
  std::vector<float> object_ranges;
  for (int r = box.y; r < box.y + box.height; ++r)
    for (int c = box.x; c < box.x + box.width; ++c)
      if (mask.at<uint8_t>(r, c) && scan.valid.at<uint8_t>(r, c))
        object_ranges.push_back(scan.range.at<float>(r, c));
  if (object_ranges.empty()) return mask.clone();
  std::nth_element(object_ranges.begin(), object_ranges.begin() + object_ranges.size() / 2,
                   object_ranges.end());
  const double median_range_m = object_ranges[object_ranges.size() / 2];
  NormalOptions normal_options;
  normal_options.window_cells = options.normal_window_cells;
  normal_options.radius_m =
      std::max(options.min_jump_m, 3.0 * (2 * options.normal_window_cells + 1) * median_range_m * cell_angle);
  const cv::Mat normal = EstimateGridNormals(CropView(scan, region), normal_options).normal;

  const cv::Mat support = SupportCells(scan, mask, region, normal, options);
  const float cos_max = static_cast<float>(std::cos(options.max_crease_deg * M_PI / 180.0));
  cv::Mat grown = mask.clone();
  std::deque<cv::Point> front;
  for (int r = region.y; r < region.y + region.height; ++r)
    for (int c = region.x; c < region.x + region.width; ++c)
      if (mask.at<uint8_t>(r, c)) front.emplace_back(c, r);
  int added = 0;
  const int max_added = static_cast<int>(options.max_growth * object_cells);
  constexpr int kDr[4] = {-1, 1, 0, 0}, kDc[4] = {0, 0, -1, 1};
  while (!front.empty()) {
    const cv::Point a = front.front();
    front.pop_front();
    const float range_a = scan.range.at<float>(a);
    const cv::Vec3f normal_a = normal.at<cv::Vec3f>(a - region.tl());
    if (!scan.valid.at<uint8_t>(a) || normal_a == cv::Vec3f()) continue;
    // A jump of more than this many cell spacings at this range is a depth edge (a surface seen at up to
    // ~80° incidence still stays under it), with a floor for range noise.
    const double jump_m = std::max(options.min_jump_m, options.jump_cells * range_a * cell_angle);
    for (int k = 0; k < 4; ++k) {
      const cv::Point b(a.x + kDc[k], a.y + kDr[k]);
      if (!region.contains(b) || grown.at<uint8_t>(b) || !scan.valid.at<uint8_t>(b)) continue;
      if ((!barrier.empty() && barrier.at<uint8_t>(b)) || support.at<uint8_t>(b)) continue;
      if (std::abs(scan.range.at<float>(b) - range_a) > jump_m) continue;
      const cv::Vec3f normal_b = normal.at<cv::Vec3f>(b - region.tl());
      if (normal_b == cv::Vec3f() || normal_a.dot(normal_b) < cos_max) continue;
      grown.at<uint8_t>(b) = 255;
      front.push_back(b);
      // A growth this large is a leak into the surroundings, not a missing part: keep the cut as it was.
      if (++added > max_added) return mask.clone();
    }
  }
  return grown;
}

}  // namespace lidarshop
