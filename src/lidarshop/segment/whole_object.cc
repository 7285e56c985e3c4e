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
#include "lidarshop/segment/part_below.h"
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

// The grid normals of a region (EstimateGridNormals over its view: the same numbers), each computed when first
// asked for. Growth reads the normals of the cells it reaches, a small part of a region that spans up to
// seven times the object's size: computing all of them took seconds at millions of cells.
class LazyNormals {
 public:
  LazyNormals() = default;
  LazyNormals(Scan view, const NormalOptions& options)
      : view_(std::move(view)),
        options_(options),
        normal_(view_.rows, view_.cols, CV_32FC3),  // written where known_ says so; never read elsewhere
        known_(cv::Mat::zeros(view_.rows, view_.cols, CV_8U)) {}
  // The normal of `cell` (the region's coordinates); 0 where the cell has no return or too few neighbours.
  const cv::Vec3f& At(cv::Point cell) {
    cv::Vec3f& normal = normal_.at<cv::Vec3f>(cell);
    uint8_t& known = known_.at<uint8_t>(cell);
    if (!known) {
      known = 1;
      float curvature;
      if (!GridNormalAt(view_, options_, cell.y, cell.x, &normal, &curvature)) normal = cv::Vec3f();
    }
    return normal;
  }

 private:
  Scan view_;
  NormalOptions options_;
  cv::Mat normal_, known_;
};

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

// The surfaces the object stands on or against: planes found by RANSAC among the cells with a return in a
// band around the object, kept when a quarter of their band cells lie outside the object's bounding box (a face
// of a missed part lies within it; the ground, a table or a wall runs beyond it). A cell of the region is on
// them when its point lies on one of the planes and its normal faces that plane's way. Asked per cell
// (At): growth asks about the cells it reaches, not about every cell of a region that can be the whole scan.
class SupportPlanes {
 public:
  // `classify` (CV_8U, may be empty = every cell of the region outside the mask): the cells that may be support.
  // `max_points` (0 = all): the planes are fitted to at most about this many band cells (a fixed stride).
  SupportPlanes(const Scan& scan, const cv::Mat& mask, const cv::Rect& region,
                const WholeObjectOptions& options, const cv::Mat& classify = cv::Mat(),
                size_t max_points = 0);
  bool At(cv::Point cell, LazyNormals& normals) const {
    if (planes_.empty() || !region_.contains(cell) || !scan_->valid.at<uint8_t>(cell)) return false;
    if (classify_.empty() ? mask_.at<uint8_t>(cell) != 0 : !classify_.at<uint8_t>(cell)) return false;
    const cv::Vec3f& p = scan_->point.at<cv::Vec3f>(cell);
    const Eigen::Vector3f point(p[0], p[1], p[2]);
    for (const Plane& plane : planes_) {
      if (std::abs(plane.fit.Distance(point)) > distance_m_) continue;
      if (std::abs(normals.At(cell - region_.tl()).dot(plane.normal)) >= cos_max_) return true;
    }
    return false;
  }
  // Every support cell of `cells` (CV_8U over the scan) as a raster.
  cv::Mat Raster(const cv::Mat& cells, LazyNormals& normals) const {
    cv::Mat support = cv::Mat::zeros(cells.size(), CV_8U);
    for (int r = region_.y; r < region_.y + region_.height; ++r)
      for (int c = region_.x; c < region_.x + region_.width; ++c)
        if (cells.at<uint8_t>(r, c) && At(cv::Point(c, r), normals)) support.at<uint8_t>(r, c) = 255;
    return support;
  }

 private:
  struct Plane {
    PlaneFit fit;
    cv::Vec3f normal;
  };
  const Scan* scan_;
  cv::Mat mask_, classify_;  // the mask as it was when the planes were fitted
  cv::Rect region_;
  double distance_m_;
  float cos_max_;
  std::vector<Plane> planes_;
};

SupportPlanes::SupportPlanes(const Scan& scan, const cv::Mat& mask, const cv::Rect& region,
                             const WholeObjectOptions& options, const cv::Mat& classify, size_t max_points)
    : scan_(&scan),
      mask_(mask.clone()),
      classify_(classify),
      region_(region),
      distance_m_(options.support_distance_m),
      cos_max_(static_cast<float>(std::cos(options.support_max_tilt_deg * M_PI / 180.0))) {
  cv::Mat band;
  if (options.support_band_cells >= std::max(region.width, region.height)) {
    // The band covers the region (the mask has cells in it): no dilation by thousands of cells.
    band = (scan.valid != 0) & (mask == 0);
  } else {
    cv::dilate(mask, band, cv::Mat(), cv::Point(-1, -1), options.support_band_cells);
    band &= ~mask;
    band &= scan.valid != 0;
  }
  PointCloud cloud;
  std::vector<cv::Point> cells;
  cv::findNonZero(band(region), cells);
  if (cells.size() < 50) return;
  if (max_points > 0 && cells.size() > max_points) {
    const size_t stride = (cells.size() + max_points - 1) / max_points;
    std::vector<cv::Point> sample;
    for (size_t i = 0; i < cells.size(); i += stride) sample.push_back(cells[i]);
    cells = std::move(sample);
  }
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
  for (const PlaneFit& plane : DetectPlanesRansac(cloud, ransac)) {
    size_t outside_box = 0;
    for (uint32_t i : plane.inliers) outside_box += !box.contains(cells[i]);
    if (4 * outside_box < plane.inliers.size()) continue;
    // A plane through much of the cut itself is a face of the object (its other half in another colour).
    if (5 * CountOnPlane(scan, mask, box, plane, options.support_distance_m) > object_cells) continue;
    planes_.push_back(
        {plane, cv::Vec3f(static_cast<float>(plane.normal.x()), static_cast<float>(plane.normal.y()),
                          static_cast<float>(plane.normal.z()))});
  }
}

// An overhanging part: cells in front of the object across a depth step (a mailbox on its post, seen from the
// post), joined to each other in depth (orientation aside: a flag at right angles to the box is the box's),
// whose every other boundary is a step down to something farther or a cell without a return. Nothing visible
// holds such a part but the object, so it rests on the object. A part that meets anything else in depth (the
// ground it stands on runs on), a barrier or the scan's edge, that has more than max_cells cells, or that lies
// behind the object where they meet, is not one; nor is a part that meets the object along more than
// max_contact_fraction of its outline (the object around it: an occluder, not a part). The seeds are the cells next to `grown` within `region`.
// Returns the cells of the first such part found (empty: none).
template <typename JumpAt, typename Free>
std::vector<cv::Point> OverhangingPart(const Scan& scan, const cv::Mat& grown, const cv::Rect& region,
                                       size_t max_cells, double max_contact_fraction, const JumpAt& jump_at,
                                       const Free& free) {
  const cv::Rect image(0, 0, scan.cols, scan.rows);
  constexpr int kDr[4] = {-1, 1, 0, 0}, kDc[4] = {0, 0, -1, 1};
  constexpr uint8_t kInPart = 1, kRejected = 2;
  cv::Mat visited = cv::Mat::zeros(grown.size(), CV_8U);
  for (int r = region.y; r < region.y + region.height; ++r) {
    for (int c = region.x; c < region.x + region.width; ++c) {
      const cv::Point a(c, r);
      if (!grown.at<uint8_t>(a) || !scan.valid.at<uint8_t>(a)) continue;
      for (int k = 0; k < 4; ++k) {
        const cv::Point seed(c + kDc[k], r + kDr[k]);
        if (!image.contains(seed) || !free(grown, seed) || visited.at<uint8_t>(seed)) continue;
        if (scan.range.at<float>(seed) >= scan.range.at<float>(a) - jump_at(a)) continue;
        std::vector<cv::Point> part = {seed};
        visited.at<uint8_t>(seed) = kInPart;
        bool held_elsewhere = false;
        int contact_edges = 0, outline_edges = 0;  // the part's outline, and where it meets the object
        for (size_t i = 0; i < part.size() && !held_elsewhere; ++i) {
          const cv::Point p = part[i];
          const float range_p = scan.range.at<float>(p);
          const double jump_m = jump_at(p);
          for (int j = 0; j < 4 && !held_elsewhere; ++j) {
            const cv::Point q(p.x + kDc[j], p.y + kDr[j]);
            if (!image.contains(q)) {
              held_elsewhere = true;  // it runs on beyond the scan
              continue;
            }
            if (visited.at<uint8_t>(q) == kInPart) continue;
            ++outline_edges;
            if (!scan.valid.at<uint8_t>(q)) continue;
            if (visited.at<uint8_t>(q) == kRejected) {
              held_elsewhere = true;  // the rest of a part already turned down
              continue;
            }
            const float range_q = scan.range.at<float>(q);
            if (grown.at<uint8_t>(q)) {
              ++contact_edges;
              held_elsewhere = range_q < range_p - jump_m;  // behind the object there
              continue;
            }
            if (range_q > range_p + jump_m) continue;  // a step down to something farther
            if (range_q < range_p - jump_m || !free(grown, q)) {
              held_elsewhere = true;  // occluded by something else, or against a barrier
              continue;
            }
            --outline_edges;  // not outline: the part goes on
            visited.at<uint8_t>(q) = kInPart;
            part.push_back(q);
            held_elsewhere = part.size() > max_cells;  // too large to be a part: it runs on
          }
        }
        // Something in front of the object, the object all around it (a leaf before a car door), is not held
        // by it: a part that rests on the object meets it along a side.
        if (!held_elsewhere && contact_edges <= max_contact_fraction * outline_edges) return part;
        for (const cv::Point& p : part) visited.at<uint8_t>(p) = kRejected;
      }
    }
  }
  return {};
}

// A part across a depth step (segment.h WholeObjectOptions::join_steps): from a cell next to the object in the
// grid, behind it across a depth step, but whose point lies within max_gap_m of the object's cell in space (a
// post under the box it holds, seen past the box's overhanging front; table legs under the top's edge), the
// cells `continues(p, q)` joins to it. The part is one of the object's when it is closed: it meets nothing that
// continues it in depth and orientation but that it may not take (a barrier, a part already turned down, the
// region's edge), and has at most max_cells cells. `enter(grown, q)`: a cell the part may take; `support(q)`: a
// cell of the support planes. Each part found is handed to `accept(part)` (which adds it to `grown` and returns
// the cells the budget has left). The seeds come from the object's cells in raster order, then from the cells
// of the parts accepted, in the order they joined (a part may hold another up: a leg's foot under its upper
// half); a part turned down stays so, and every cell is explored at most once. Returns the number of parts
// accepted. (Passes over the region repeated until one added nothing took 92 passes of 0.14 s each on a
// 5.4 M-ray station, each joining a few small parts next to the last pass's.)
template <typename JumpAt, typename Enter, typename Continues, typename Support, typename Accept>
int PartsAcrossStep(const Scan& scan, const cv::Mat& grown, const cv::Rect& region, size_t max_cells,
                    double max_gap_m, const JumpAt& jump_at, const Enter& enter, const Continues& continues,
                    const Support& support, const Accept& accept) {
  using whole_object_internal::GrowClosedPart, whole_object_internal::kInPart,
      whole_object_internal::kRejected, whole_object_internal::kPartDc, whole_object_internal::kPartDr;
  const float max_gap_sq = static_cast<float>(max_gap_m * max_gap_m);
  // What it stands on, or another surface meeting it at a crease (the ground at a post's foot, where the box
  // holding the post keeps the ground out of the support planes' band), does not continue a part.
  const auto stops = [&](const cv::Point& p, const cv::Point& q) { return support(q) || !continues(p, q); };
  cv::Rect object_box = cv::boundingRect(grown);
  cv::Mat visited = cv::Mat::zeros(grown.size(), CV_8U);
  std::deque<cv::Point> joined;  // cells of accepted parts, still to seed from
  int accepted = 0;
  // Explores the parts seeded next to object cell `a`; false when the budget is spent.
  const auto from = [&](cv::Point a) {
    if (!grown.at<uint8_t>(a) || !scan.valid.at<uint8_t>(a)) return true;
    const cv::Vec3f& point_a = scan.point.at<cv::Vec3f>(a);
    for (int k = 0; k < 4; ++k) {
      const cv::Point seed(a.x + kPartDc[k], a.y + kPartDr[k]);
      if (!region.contains(seed) || visited.at<uint8_t>(seed) || !enter(grown, seed)) continue;
      // Behind the object: a part in front of it that stands on the ground may as well be an occluder (a crate
      // before a post's foot) as what the object rests on.
      if (scan.range.at<float>(seed) <= scan.range.at<float>(a) + jump_at(a)) continue;
      const cv::Vec3f gap = scan.point.at<cv::Vec3f>(seed) - point_a;
      if (gap.dot(gap) > max_gap_sq) continue;
      std::vector<cv::Point> part = {seed};
      visited.at<uint8_t>(seed) = kInPart;
      const bool closed =
          GrowClosedPart(scan, grown, region, max_cells, jump_at, enter, stops, visited, part);
      // What an object holds up lies under it, within its width (a post, legs); a closed surface beside it
      // (a door recess behind a person, a strip of kerb behind a post's foot) is not held by it.
      if (closed) {
        const cv::Rect part_box = cv::boundingRect(part);
        if (part_box.x >= object_box.x - 2 && part_box.br().x <= object_box.br().x + 2 &&
            part_box.y > object_box.y) {
          // The part is the object's now (kInPart marks stay: grown holds it from here on).
          object_box |= part_box;
          ++accepted;
          max_cells = accept(part);
          if (max_cells == 0) return false;
          joined.insert(joined.end(), part.begin(), part.end());
          continue;
        }
      }
      for (const cv::Point& p : part) visited.at<uint8_t>(p) = kRejected;
    }
    return true;
  };
  for (int r = region.y; r < region.y + region.height; ++r)
    for (int c = region.x; c < region.x + region.width; ++c)
      if (!from(cv::Point(c, r))) return accepted;
  while (!joined.empty()) {
    const cv::Point a = joined.front();
    joined.pop_front();
    if (!from(a)) return accepted;
  }
  return accepted;
}

// How deep into a cut a fringe of its support can reach, cells.
constexpr int kFringeCells = 4;

// The object's box, the region around it that growth may reach, and the grid normals there.
struct ObjectFrame {
  cv::Rect box, region;
  double cell_angle = 0;
  LazyNormals normals;  // over the region
};

// `margin` cells around the mask's box make the region (-1 = three times the box's larger side on every side:
// a box on a post, stroked on the box, has a post up to three times the box's height below it). False when
// the mask holds no cell with a return.
bool FrameOf(const Scan& scan, const cv::Mat& mask, const WholeObjectOptions& options, int margin,
             ObjectFrame* frame) {
  frame->box = cv::boundingRect(mask);
  const cv::Rect& box = frame->box;
  if (margin < 0) margin = 3 * std::max(box.width, box.height);
  frame->region = cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
                  cv::Rect(0, 0, scan.cols, scan.rows);
  frame->cell_angle = MeanCellAngle(scan);
  // Normals from the window's cells near the centre only: a window across a depth edge would tilt the
  // normals of the background cells along the object's outline, and growth would crawl along that ring.
  std::vector<float> object_ranges;
  for (int r = box.y; r < box.y + box.height; ++r)
    for (int c = box.x; c < box.x + box.width; ++c)
      if (mask.at<uint8_t>(r, c) && scan.valid.at<uint8_t>(r, c))
        object_ranges.push_back(scan.range.at<float>(r, c));
  if (object_ranges.empty()) return false;
  std::nth_element(object_ranges.begin(), object_ranges.begin() + object_ranges.size() / 2,
                   object_ranges.end());
  const double median_range_m = object_ranges[object_ranges.size() / 2];
  NormalOptions normal_options;
  normal_options.window_cells = options.normal_window_cells;
  normal_options.radius_m = std::max(
      options.min_jump_m, 3.0 * (2 * options.normal_window_cells + 1) * median_range_m * frame->cell_angle);
  frame->normals = LazyNormals(CropView(scan, frame->region), normal_options);
  return true;
}

}  // namespace

cv::Mat SupportSurfaceCells(const Scan& scan, const cv::Mat& mask, const WholeObjectOptions& options) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && mask.size() == cv::Size(scan.cols, scan.rows));
  if (cv::countNonZero(mask) == 0) return cv::Mat::zeros(mask.size(), CV_8U);
  // The mask's cells near its outline: a fringe of support the cut took lies there, not inside.
  cv::Mat inner;
  cv::erode(mask, inner, cv::Mat(), cv::Point(-1, -1), kFringeCells, cv::BORDER_CONSTANT, 0);
  const cv::Mat fringe = mask & ~inner;
  // Only the support band and the normals' window around the mask matter here.
  const int margin = options.support_band_cells + options.normal_window_cells + 1;
  ObjectFrame frame;
  if (!FrameOf(scan, mask, options, margin, &frame)) return cv::Mat::zeros(mask.size(), CV_8U);
  return SupportPlanes(scan, mask, frame.region, options, fringe).Raster(fringe, frame.normals);
}

cv::Mat GrowWholeObject(const Scan& scan, const cv::Mat& mask, const cv::Mat& barrier,
                        const WholeObjectOptions& options) {
  LIDARSHOP_CHECK(mask.type() == CV_8U && mask.size() == cv::Size(scan.cols, scan.rows));
  LIDARSHOP_CHECK(barrier.empty() || (barrier.type() == CV_8U && barrier.size() == mask.size()));
  const int object_cells = cv::countNonZero(mask);
  if (object_cells == 0) return mask.clone();
  ObjectFrame frame;
  if (!FrameOf(scan, mask, options, /*margin=*/-1, &frame)) return mask.clone();
  const cv::Rect& box = frame.box;
  const cv::Rect& region = frame.region;
  const double cell_angle = frame.cell_angle;
  LazyNormals& normals = frame.normals;
  const SupportPlanes support(scan, mask, region, options);
  const float cos_max = static_cast<float>(std::cos(options.max_crease_deg * M_PI / 180.0));
  // A jump of more than this many cell spacings at this range is a depth edge (a surface seen at up to
  // ~80° incidence still stays under it), with a floor for range noise.
  const auto jump_at = [&](cv::Point a) {
    return std::max(options.min_jump_m, options.jump_cells * scan.range.at<float>(a) * cell_angle);
  };
  // A cell an overhang may take: valid, not yet object and not barred (it may lie beyond the region: its size
  // is bounded by the growth's budget instead). (Support planes do not
  // matter there: a part on a support surface runs on in depth across it to the region's edge, and the front
  // face of an overhanging box wider than the cut is easily taken for a support plane.)
  const auto free = [&](const cv::Mat& grown, cv::Point b) {
    return !grown.at<uint8_t>(b) && scan.valid.at<uint8_t>(b) && (barrier.empty() || !barrier.at<uint8_t>(b));
  };
  // A cell growth may enter: inside the region (its normals are known only there: reading one outside read
  // memory past the normals' matrix, and the cut changed with the thread count and from run to run), free and
  // not support.
  const auto open = [&](const cv::Mat& grown, cv::Point b) {
    return region.contains(b) && free(grown, b) && !support.At(b, normals);
  };
  // The continuous growth stays within the box's own size around it (beyond that it is a leak anyway); the
  // parts across a step may reach the whole region (a post three times the box's height).
  const int inner_margin = std::max(box.width, box.height);
  const cv::Rect inner = cv::Rect(box.x - inner_margin, box.y - inner_margin, box.width + 2 * inner_margin,
                                  box.height + 2 * inner_margin) &
                         region;
  const auto open_inner = [&](const cv::Mat& grown, cv::Point b) {
    return inner.contains(b) && open(grown, b);
  };
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
    const cv::Vec3f normal_a = normals.At(a - region.tl());
    if (!scan.valid.at<uint8_t>(a) || normal_a == cv::Vec3f()) continue;
    const double jump_m = jump_at(a);
    for (int k = 0; k < 4; ++k) {
      const cv::Point b(a.x + kDc[k], a.y + kDr[k]);
      if (!open_inner(grown, b)) continue;
      if (std::abs(scan.range.at<float>(b) - range_a) > jump_m) continue;
      const cv::Vec3f normal_b = normals.At(b - region.tl());
      if (normal_b == cv::Vec3f() || normal_a.dot(normal_b) < cos_max) continue;
      grown.at<uint8_t>(b) = 255;
      front.push_back(b);
      // A growth this large is a leak into the surroundings, not a missing part: keep the cut as it was.
      if (++added > max_added) {
        grown = mask.clone();
        front.clear();
        added = 0;
        break;
      }
    }
  }
  // Overhanging parts are closed by depth steps on every side, so they cannot leak: they join even when the
  // growth above did (each one closed in depth, so growth from it would add nothing).
  while (options.join_overhangs) {
    const std::vector<cv::Point> overhang =
        OverhangingPart(scan, grown, region, static_cast<size_t>(std::max(0, max_added - added)),
                        options.overhang_max_contact, jump_at, free);
    if (overhang.empty()) break;
    added += static_cast<int>(overhang.size());
    for (const cv::Point& cell : overhang) grown.at<uint8_t>(cell) = 255;
  }
  // Closed parts across a depth step that touch the object in space join it (the post under a box), each
  // within what is left of the budget.
  const float cos_max_part = static_cast<float>(std::cos(options.join_max_crease_deg * M_PI / 180.0));
  const auto continues = [&](cv::Point p, cv::Point q) {
    const cv::Vec3f normal_p = normals.At(p - region.tl()), normal_q = normals.At(q - region.tl());
    return normal_p != cv::Vec3f() && normal_q != cv::Vec3f() && normal_p.dot(normal_q) >= cos_max_part;
  };
  // The support planes of the whole region: a part's foot may stand on ground far from the cut (a post under
  // a box), beyond the band the cut's own support planes are fitted to.
  if (!options.join_steps && !options.join_rests_on) return grown;
  WholeObjectOptions wide = options;
  wide.support_band_cells = std::max(region.width, region.height);
  const SupportPlanes wide_support(scan, grown, region, wide, cv::Mat(), /*max_points=*/20000);
  const auto on_support = [&](cv::Point q) { return support.At(q, normals) || wide_support.At(q, normals); };
  const auto enter = [&](const cv::Mat& grown, cv::Point b) {
    return open(grown, b) && !wide_support.At(b, normals);
  };
  // A closed part in front of the object and below it that the object stands on joins it (the lower crate of
  // a stack), each within what is left of its own budget (a lower crate can be many times the box on it, and
  // closed parts cannot leak); a part it joins may hold up another.
  // Only the region's support planes stop it: the planes of the band around the cut hold the crate's top,
  // the very surface the box stands on.
  const int max_rests_on = static_cast<int>(options.rests_on_max_growth * object_cells);
  const auto wide_only = [&](cv::Point q) { return wide_support.At(q, normals); };
  const auto enter_below = [&](const cv::Mat& grown, cv::Point b) {
    return region.contains(b) && free(grown, b) && !wide_only(b);
  };
  while (options.join_rests_on && added < max_rests_on) {
    const std::vector<cv::Point> below =
        whole_object_internal::PartItRestsOn(scan, grown, region, static_cast<size_t>(max_rests_on - added),
                                             options.support_distance_m, jump_at, enter_below, wide_only);
    if (below.empty()) break;
    added += static_cast<int>(below.size());
    for (const cv::Point& cell : below) grown.at<uint8_t>(cell) = 255;
  }
  if (!options.join_steps || added >= max_added) return grown;
  const auto accept = [&](const std::vector<cv::Point>& part) {
    added += static_cast<int>(part.size());
    for (const cv::Point& cell : part) grown.at<uint8_t>(cell) = 255;
    return static_cast<size_t>(std::max(0, max_added - added));
  };
  PartsAcrossStep(scan, grown, region, static_cast<size_t>(max_added - added), options.join_max_gap_m,
                  jump_at, enter, continues, on_support, accept);
  return grown;
}

}  // namespace lidarshop
