// Step 1 of fill/surface_planes.h: the planes seen in the band of known cells around one part of the hole.
#include "lidarshop/fill/surface_planes.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"

namespace lidarshop::fill_internal {
namespace {

// cos 8°: planes this parallel, within relief_m of each other, are one surface and its relief.
constexpr double kParallelCos = 0.99;

// cos 10°: a cell whose grid normal is within 10° of a plane's faces the plane's way.
constexpr float kAgreeingNormal = 0.985f;

// A plane holding this share of the band's cells (and 30) is kept when it is seen on both sides of the hole.
constexpr double kSmallPlaneShare = 0.01;

// A box of grid cells, [x0, x1) x [y0, y1).
struct Rect2 {
  int x0, y0, x1, y1;
  void Add(int x, int y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x + 1);
    y1 = std::max(y1, y + 1);
  }
  // Reaches past `part` on two opposite sides: left and right of it, or above and below.
  bool Spans(const Rect2& part) const {
    return (x0 < part.x0 && x1 > part.x1) || (y0 < part.y0 && y1 > part.y1);
  }
};

// The largest 8-connected part (on the grid of `size`) of the cells `subset` (indices into `cells`).
std::vector<uint32_t> LargestConnectedPart(const std::vector<uint32_t>& subset,
                                           const std::vector<cv::Point>& cells, cv::Size size) {
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  for (uint32_t i : subset) mask.at<uint8_t>(cells[i]) = 255;
  cv::Mat ids, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, ids, stats, centroids, 8, CV_32S);
  int best = 0;
  for (int id = 1; id < count; ++id)
    if (best == 0 || stats.at<int>(id, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = id;
  std::vector<uint32_t> part;
  for (uint32_t i : subset)
    if (ids.at<int32_t>(cells[i]) == best) part.push_back(i);
  return part;
}

// The plane of most band cells that lie on it and face its way, among `remaining` (indices into `points`):
// hypotheses are planes through one cell's point with its grid normal (1-point RANSAC with normals), scored
// on at most kScoredCells of the cells. RANSAC through three points alone prefers the plane through a
// flight of steps' nosings, which holds more cells within the distance than any one tread; a tread's cells
// face up, not along that plane. Its facing inliers, increasing; empty when no cell has a normal.
constexpr int kFacingHypotheses = 200;
constexpr size_t kScoredCells = 4000;
std::vector<uint32_t> FacingPlaneCells(const std::vector<Eigen::Vector3f>& points,
                                       const std::vector<cv::Vec3f>& normals,
                                       const std::vector<uint32_t>& remaining, double threshold_m,
                                       uint64_t seed) {
  std::mt19937_64 random(seed);
  std::vector<uint32_t> with_normal;
  for (uint32_t i : remaining)
    if (normals[i].dot(normals[i]) > 0.5f) with_normal.push_back(i);
  if (with_normal.empty()) return {};
  std::vector<uint32_t> scored = with_normal;
  if (scored.size() > kScoredCells) {
    // A fixed sample (partial Fisher–Yates with the generator's raw draws: the same on every platform).
    for (size_t k = 0; k < kScoredCells; ++k)
      std::swap(scored[k], scored[k + random() % (scored.size() - k)]);
    scored.resize(kScoredCells);
  }
  auto on_plane = [&](uint32_t i, const cv::Vec3f& n, double offset) {
    const Eigen::Vector3f& p = points[i];
    return std::abs(n[0] * p.x() + n[1] * p.y() + n[2] * p.z() + offset) <= threshold_m &&
           std::abs(n.dot(normals[i])) >= kAgreeingNormal;
  };
  size_t best_count = 0;
  uint32_t best_seed_cell = with_normal[0];
  for (int h = 0; h < kFacingHypotheses; ++h) {
    const uint32_t c = with_normal[random() % with_normal.size()];
    const cv::Vec3f n = normals[c];
    const Eigen::Vector3f& p = points[c];
    const double offset = -(n[0] * p.x() + n[1] * p.y() + n[2] * p.z());
    size_t count = 0;
    for (uint32_t i : scored) count += on_plane(i, n, offset);
    if (count > best_count) {
      best_count = count;
      best_seed_cell = c;
    }
  }
  const cv::Vec3f n = normals[best_seed_cell];
  const Eigen::Vector3f& p = points[best_seed_cell];
  const double offset = -(n[0] * p.x() + n[1] * p.y() + n[2] * p.z());
  std::vector<uint32_t> cells;
  for (uint32_t i : with_normal)
    if (on_plane(i, n, offset)) cells.push_back(i);
  return cells;
}

}  // namespace

std::vector<SeenPlane> BandPlanes(const KnownCells& known, const cv::Mat& part_id, int id,
                                  const cv::Rect& box, int part_cells, const FillPlaneOptions& options,
                                  uint64_t seed, double* threshold_m) {
  int band = options.band_cells;
  if (band <= 0) {
    const double diameter = 2.0 * std::sqrt(part_cells / M_PI);
    band = std::clamp(static_cast<int>(std::lround(diameter / 4.0)), 8, 80);
  }
  const cv::Rect roi = cv::Rect(box.x - band, box.y - band, box.width + 2 * band, box.height + 2 * band) &
                       cv::Rect(0, 0, known.range.cols, known.range.rows);
  // The part over the band's box only: a hole of many small parts must not cost the whole scan per part.
  const cv::Mat part = part_id(roi) == id;
  cv::Mat near_part;
  cv::dilate(part, near_part, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * band + 1, 2 * band + 1}));
  near_part &= known.valid(roi);
  std::vector<cv::Point> cells;
  cv::findNonZero(near_part, cells);
  // Distance of every band cell from the part: a plane seen only on the hole's rim is what the cut left of
  // the object itself (its face, missed by a cell or two), not a surface that runs on behind it.
  cv::Mat from_part;
  cv::distanceTransform(part == 0, from_part, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  if (cells.size() < 50) return {};
  // Grid normals of the band (a view of the known cells only), to tell a plane the cells lie on from one that
  // only runs through them (the plane through the nosings of a flight of steps).
  Scan band_view;
  band_view.rows = roi.height;
  band_view.cols = roi.width;
  band_view.valid = known.valid(roi);
  band_view.point = cv::Mat(roi.size(), CV_32FC3, cv::Scalar::all(0));
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      if (!band_view.valid.at<uint8_t>(y, x)) continue;
      const Eigen::Vector3f p = known.PointAt(y + roi.y, x + roi.x);
      band_view.point.at<cv::Vec3f>(y, x) = cv::Vec3f(p.x(), p.y(), p.z());
    }
  }
  NormalOptions normal_options;
  normal_options.window_cells = 2;
  const cv::Mat normal = EstimateGridNormals(band_view, normal_options).normal;
  std::vector<cv::Vec3f> cell_normals;
  cell_normals.reserve(cells.size());
  for (const cv::Point& c : cells) cell_normals.push_back(normal.at<cv::Vec3f>(c));
  PointCloud cloud;
  std::vector<float> ranges;
  cloud.points.reserve(cells.size());
  ranges.reserve(cells.size());
  for (const cv::Point& c : cells) {
    cloud.points.push_back(known.PointAt(c.y + roi.y, c.x + roi.x));
    ranges.push_back(known.range.at<float>(c.y + roi.y, c.x + roi.x));
  }
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  *threshold_m = options.inlier_m + options.inlier_per_m * ranges[ranges.size() / 2];

  // A plane holding min_share of the band is kept; a smaller one (a kerb's face, a stair riser: 10–20 rows)
  // only when it continues past the hole, seen on both of its sides.
  const size_t large = static_cast<size_t>(
      std::max(50, static_cast<int>(options.min_share * static_cast<double>(cells.size()))));
  const size_t small = static_cast<size_t>(
      std::max(30, static_cast<int>(kSmallPlaneShare * static_cast<double>(cells.size()))));
  const Rect2 part_box{box.x - roi.x, box.y - roi.y, box.x - roi.x + box.width, box.y - roi.y + box.height};
  std::vector<uint32_t> remaining(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) remaining[i] = static_cast<uint32_t>(i);
  std::vector<SeenPlane> planes;
  const int attempts = 2 * options.max_planes;
  for (int attempt = 0; attempt < attempts && static_cast<int>(planes.size()) < options.max_planes;
       ++attempt) {
    if (remaining.size() < small) break;
    const std::vector<uint32_t> hypothesis = FacingPlaneCells(
        cloud.points, cell_normals, remaining, *threshold_m, seed + static_cast<uint64_t>(attempt));
    if (hypothesis.size() < small) break;
    // The hypothesis's cells may lie on two parallel surfaces at once (the road and the pavement behind a kerb,
    // 2° apart, both within the inlier distance somewhere): the plane is fitted to the largest grid-connected
    // part of them, then to every remaining cell within the distance that faces the fitted plane's way. Cells
    // within the distance that face elsewhere (a riser's cells at a tread's edge) stay for a plane of their own.
    auto facing = [&](uint32_t i, const PlaneFit& f) {
      const cv::Vec3f& n = cell_normals[i];
      return std::abs(n[0] * f.normal.x() + n[1] * f.normal.y() + n[2] * f.normal.z()) >= kAgreeingNormal;
    };
    PlaneFit fit;
    fit.normal = Eigen::Vector3d(cell_normals[hypothesis[0]][0], cell_normals[hypothesis[0]][1],
                                 cell_normals[hypothesis[0]][2]);
    fit.inliers = LargestConnectedPart(hypothesis, cells, roi.size());
    if (fit.inliers.size() < 3) break;
    RefitPlane(cloud.points, &fit);
    std::vector<uint32_t> inliers;
    std::vector<uint32_t> kept;
    size_t within = 0;  // remaining cells within the distance, facing any way
    // Twice: the part's plane gathers the surface's cells beyond the part (the face on the hole's other
    // side), and the plane refitted to all of them is the least-squares plane of the whole surface.
    for (int pass = 0; pass < 2; ++pass) {
      kept.clear();
      inliers.clear();
      within = 0;
      for (uint32_t i : remaining) {
        const bool near = std::abs(fit.Distance(cloud.points[i])) <= *threshold_m;
        within += near;
        (near && facing(i, fit) ? inliers : kept).push_back(i);
      }
      if (pass == 0 && inliers.size() >= 3) {
        fit.inliers = inliers;
        RefitPlane(cloud.points, &fit);
      }
    }
    if (inliers.size() < small || 2 * inliers.size() < within) {
      // The refit lost its support, or most cells on the plane face elsewhere (not a surface): drop the
      // hypothesis's cells and go on.
      std::vector<uint32_t> rest;
      std::set_difference(remaining.begin(), remaining.end(), hypothesis.begin(), hypothesis.end(),
                          std::back_inserter(rest));
      remaining = std::move(rest);
      continue;
    }
    remaining = std::move(kept);
    SeenPlane plane;
    plane.normal = fit.normal;
    plane.offset_m = fit.offset_m;
    if (std::abs(plane.offset_m) < 1e-6) continue;  // a plane through the scanner is seen edge-on
    if (plane.offset_m < 0) {
      plane.normal = -plane.normal;
      plane.offset_m = -plane.offset_m;
    }
    plane.seen.reserve(inliers.size());
    size_t outer = 0;
    Rect2 seen_box{INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN};
    for (uint32_t i : inliers) {  // every one faces the plane's way
      plane.seen.push_back(cloud.points[i]);
      outer += from_part.at<float>(cells[i]) > 0.5f * band;
      seen_box.Add(cells[i].x, cells[i].y);
    }
    if (4 * outer < plane.seen.size()) continue;                           // only on the rim
    if (plane.seen.size() < large && !seen_box.Spans(part_box)) continue;  // small, and not past the hole
    // A facade's window panes are a plane of their own a little behind it; they are the facade's relief (a
    // copied pane lands at its offset from the facade), not a surface a cell copied from no plane may snap to.
    const bool relief_of_earlier = std::any_of(planes.begin(), planes.end(), [&](const SeenPlane& earlier) {
      return std::abs(plane.normal.z()) < kUprightNormalZ &&
             earlier.normal.dot(plane.normal) > kParallelCos &&
             std::abs(earlier.offset_m - plane.offset_m) <= options.relief_m;
    });
    if (relief_of_earlier) continue;
    planes.push_back(std::move(plane));
  }
  return planes;
}

}  // namespace lidarshop::fill_internal
