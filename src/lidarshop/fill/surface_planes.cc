#include "lidarshop/fill/surface_planes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross
#include <opencv2/imgproc.hpp>

#include "lidarshop/fill/rim_planes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

void FillPlaneOptions::Check() const { Validate(*this); }

namespace fill_internal {
namespace {

constexpr size_t kMaxPlanes = 20;  // the range of FillPlaneOptions::max_planes

// The mean angle between neighbouring rays in `box`, radians.
double MeanRaySpacing(const cv::Mat& direction, const cv::Rect& box) {
  double sum = 0;
  int count = 0;
  for (int y = box.y; y < box.y + box.height; ++y) {
    for (int x = box.x; x < box.x + box.width; ++x) {
      const cv::Vec3f d = direction.at<cv::Vec3f>(y, x);
      if (x + 1 < direction.cols) {
        sum +=
            std::acos(std::clamp(static_cast<double>(d.dot(direction.at<cv::Vec3f>(y, x + 1))), -1.0, 1.0));
        ++count;
      }
      if (y + 1 < direction.rows) {
        sum +=
            std::acos(std::clamp(static_cast<double>(d.dot(direction.at<cv::Vec3f>(y + 1, x))), -1.0, 1.0));
        ++count;
      }
    }
  }
  return count ? sum / count : 0.0;
}

// How two planes meet, from where their seen parts lie relative to each other. Nearly parallel planes (a
// road and a pavement) do not meet; nor do planes whose parts lie on mixed sides (a wall end before a facade).
Meeting HowTheyMeet(const SeenPlane& a, const SeenPlane& b, double threshold_m) {
  if (std::abs(a.normal.dot(b.normal)) > std::cos(20.0 * M_PI / 180.0)) return Meeting::kNone;
  auto sides = [threshold_m](const SeenPlane& from, const SeenPlane& to, double* front, double* behind) {
    int in_front = 0, in_behind = 0;
    for (const Eigen::Vector3f& p : from.seen) {
      const double d = to.SignedDistance(p);
      in_front += d > threshold_m;
      in_behind += d < -threshold_m;
    }
    const int total = std::max(in_front + in_behind, 1);
    *front = static_cast<double>(in_front) / total;
    *behind = static_cast<double>(in_behind) / total;
    return in_front + in_behind;
  };
  double front_a = 0, behind_a = 0, front_b = 0, behind_b = 0;
  if (sides(a, b, &front_a, &behind_a) < 20 || sides(b, a, &front_b, &behind_b) < 20) return Meeting::kNone;
  if (front_a >= 0.9 && front_b >= 0.9) return Meeting::kConcave;
  if (behind_a >= 0.9 && behind_b >= 0.9) return Meeting::kConvex;
  return Meeting::kNone;
}

PartPlanes FindPartPlanes(const KnownCells& known, const cv::Mat& part_id, int id, const cv::Rect& box,
                          int part_cells, const FillPlaneOptions& options, uint64_t seed) {
  PartPlanes part;
  double threshold_m = 0;
  part.planes = BandPlanes(known, part_id, id, box, part_cells, options, seed, &threshold_m);
  const size_t n = part.planes.size();
  part.meeting.assign(n * n, Meeting::kNone);
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b)
      part.meeting[a * n + b] = part.meeting[b * n + a] =
          HowTheyMeet(part.planes[a], part.planes[b], threshold_m);
  part.spacing_rad = MeanRaySpacing(known.direction, box);
  return part;
}

// The plane a source cell lies on, facing its way, within relief_m (the nearest), and its signed offset from
// it; −1 when none.
int SourcePlane(const PartPlanes& part, const KnownCells& known, const cv::Vec2i& from, double relief_m,
                double* offset_m) {
  Eigen::Vector3f normal;
  if (from[0] < 0 || !known.valid.at<uint8_t>(from[0], from[1]) ||
      !CellNormal(known, from[0], from[1], &normal)) {
    return -1;
  }
  const Eigen::Vector3f q = known.PointAt(from[0], from[1]);
  int best = -1;
  for (size_t k = 0; k < part.planes.size(); ++k) {
    const double d = part.planes[k].SignedDistance(q);
    if (std::abs(d) > relief_m || std::abs(normal.cast<double>().dot(part.planes[k].normal)) < kFacingNormal)
      continue;
    if (best < 0 || std::abs(d) < std::abs(*offset_m)) {
      best = static_cast<int>(k);
      *offset_m = d;
    }
  }
  return best;
}

// The offset from plane `k` that the known cells around hole cell (y, x) agree on: the nearest known cells
// outside the hole (`hole`, CV_8U) left and right of it, and above and below it, each pair counted when both
// face the plane's way within relief_m of it and agree within `tolerance_m`. A recess's edge hidden by the
// object and running up through the hole leaves the pair above and below on the cell's side of it (and the
// pair left and right disagreeing); one running across, the pair left and right. True when one pair agrees,
// or both agree with each other; `offset_m` receives their mean. A patch is matched on the range's gradients,
// which are the same on a facade and on a window recess parallel to it: the relief a patch brings is a guess
// that the cells around the hole can overrule.
bool SurroundOffset(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole, int y, int x,
                    size_t k, double relief_m, double tolerance_m, double* offset_m) {
  constexpr std::array<std::array<int, 2>, 4> kSteps{{{0, -1}, {0, 1}, {-1, 0}, {1, 0}}};
  std::array<bool, 4> on{};
  std::array<double, 4> offset{};
  for (size_t s = 0; s < kSteps.size(); ++s) {
    int yy = y, xx = x;
    do {
      yy += kSteps[s][0];
      xx += kSteps[s][1];
    } while (yy >= 0 && xx >= 0 && yy < hole.rows && xx < hole.cols && hole.at<uint8_t>(yy, xx));
    Eigen::Vector3f normal;
    if (!known.Usable(yy, xx) || !CellNormal(known, yy, xx, &normal)) continue;
    if (std::abs(normal.cast<double>().dot(part.planes[k].normal)) < kFacingNormal) continue;
    offset[s] = part.planes[k].SignedDistance(known.PointAt(yy, xx));
    on[s] = std::abs(offset[s]) <= relief_m;
  }
  const bool row = on[0] && on[1] && std::abs(offset[0] - offset[1]) <= tolerance_m;
  const bool column = on[2] && on[3] && std::abs(offset[2] - offset[3]) <= tolerance_m;
  const double row_mean = 0.5 * (offset[0] + offset[1]), column_mean = 0.5 * (offset[2] + offset[3]);
  if (row && column) {
    if (std::abs(row_mean - column_mean) > tolerance_m)
      return false;  // a hidden recess's corner: the patch's
    *offset_m = 0.5 * (row_mean + column_mean);
  } else if (row || column) {
    *offset_m = row ? row_mean : column_mean;
  } else {
    return false;
  }
  return true;
}

// A hole cell in a narrow gap — at most kNarrowGapCells between the known cells left and right of it, or
// above and below (a post's column, a leg) — whose two known cells lie on one plane at one relief: the plane
// `*plane` and that relief `*offset_m`. Such a surface runs on behind a thin object; a patch copied from
// another surface (a neighbour's side, whose plane the ray meets a little beyond the wall) has no say there.
constexpr int kNarrowGapCells = 16;
bool NarrowGapPlane(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole, int y, int x,
                    double relief_m, int* plane, double* offset_m) {
  int gap = 0;
  for (int pair = 0; pair < 2; ++pair)
    if (PairPlane(part, known, hole, y, x, pair, kNarrowGapCells, relief_m, plane, offset_m, &gap))
      return true;
  return false;
}

// The range of a hole cell (ray `dir`, reconstructed range `r`, copied from `from`) on the planes of its
// part; 0 = keep the reconstruction.
double RangeOnPlanes(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole,
                     const cv::Point& cell, const cv::Vec2i& from, const cv::Vec3f& dir, double r,
                     double agreement_m, const FillPlaneOptions& options) {
  const Eigen::Vector3d ray(dir[0], dir[1], dir[2]);
  int gap_plane = -1;
  double gap_offset = 0;
  if (NarrowGapPlane(part, known, hole, cell.y, cell.x, options.relief_m, &gap_plane, &gap_offset)) {
    const SeenPlane& p = part.planes[static_cast<size_t>(gap_plane)];
    const double facing = p.normal.dot(ray);
    if (std::abs(facing) >= 1e-6) {
      const double along = (gap_offset - p.offset_m) / facing;
      if (along > 0 && std::abs(along - r) <= options.tolerance * r) return along;
    }
  }
  double source_offset = 0;
  const int source_plane = SourcePlane(part, known, from, options.relief_m, &source_offset);
  // The source's relief, unless the cells around the hole agree on another (a patch of a window recess
  // copied onto the plain facade beside it, or of the facade into a recess).
  double around = 0;
  if (source_plane >= 0 &&
      SurroundOffset(part, known, hole, cell.y, cell.x, static_cast<size_t>(source_plane), options.relief_m,
                     kReliefStepM, &around) &&
      std::abs(around - source_offset) > kReliefStepM)
    source_offset = around;
  const size_t n = part.planes.size();
  // No allocation per cell: FillPlaneOptions::max_planes is at most kMaxPlanes (checked with the options).
  LIDARSHOP_CHECK(n <= kMaxPlanes);
  std::array<double, kMaxPlanes> along{};
  std::array<char, kMaxPlanes> candidate{};
  int best = -1;
  for (size_t k = 0; k < n; ++k) {
    const double facing = part.planes[k].normal.dot(ray);
    if (std::abs(facing) < 1e-6) continue;
    const double offset = static_cast<int>(k) == source_plane ? source_offset : 0.0;
    along[k] = (offset - part.planes[k].offset_m) / facing;
    if (!(along[k] > 0) || std::abs(along[k] - r) > options.tolerance * r) continue;
    candidate[k] = 1;
    if (best < 0 || std::abs(along[k] - r) < std::abs(along[static_cast<size_t>(best)] - r))
      best = static_cast<int>(k);
  }
  if (best < 0) return 0;
  // The source's own surface, when it is a candidate: of two parallel planes a few centimetres apart (a facade
  // and its window recesses) the reconstruction cannot tell which, the patch can. A cell copied from no plane
  // goes only onto a plane the reconstruction already agrees with.
  if (source_plane >= 0 && candidate[static_cast<size_t>(source_plane)]) {
    best = source_plane;
  } else if (std::abs(along[static_cast<size_t>(best)] - r) > agreement_m) {
    return 0;
  }
  // The order of the surroundings: the nearer of two planes meeting concavely, the farther of two meeting
  // convexly (bounded: three planes could send it round).
  for (size_t round = 0; round < n; ++round) {
    size_t next = static_cast<size_t>(best);
    for (size_t k = 0; k < n; ++k) {
      if (!candidate[k]) continue;
      const Meeting m = part.At(static_cast<size_t>(best), k);
      if ((m == Meeting::kConcave && along[k] < along[next]) ||
          (m == Meeting::kConvex && along[k] > along[next]))
        next = k;
    }
    if (static_cast<int>(next) == best) break;
    best = static_cast<int>(next);
  }
  return along[static_cast<size_t>(best)];
}

}  // namespace

bool CellNormal(const KnownCells& known, int y, int x, Eigen::Vector3f* normal) {
  constexpr int kReach = 2;
  auto end = [&](int dy, int dx, Eigen::Vector3f* p) {
    for (int step = kReach; step >= 0; --step) {
      if (known.Usable(y + dy * step, x + dx * step)) {
        *p = known.PointAt(y + dy * step, x + dx * step);
        return true;
      }
    }
    return false;
  };
  Eigen::Vector3f left, right, up, down;
  if (!end(0, -1, &left) || !end(0, 1, &right) || !end(-1, 0, &up) || !end(1, 0, &down)) return false;
  const Eigen::Vector3f n = (right - left).cross(down - up);
  if (n.norm() <= 0) return false;
  *normal = n.normalized();
  return true;
}

int64_t SnapToPlanes(const cv::Mat& range, const cv::Mat& known_valid, const cv::Mat& direction,
                     const cv::Mat& hole, const cv::Mat& has_return, const cv::Mat& source,
                     const FillPlaneOptions& options, uint64_t seed, cv::Mat* hole_range) {
  if (!options.enabled) return 0;
  const KnownCells known{range, known_valid, direction};
  cv::Mat part_id, stats, centroids;
  const int part_count = cv::connectedComponentsWithStats(hole != 0, part_id, stats, centroids, 8, CV_32S);
  cv::Mat to_border;
  cv::distanceTransform(hole != 0, to_border, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  int64_t moved = 0;
  for (int id = 1; id < part_count; ++id) {
    const cv::Rect box(stats.at<int>(id, cv::CC_STAT_LEFT), stats.at<int>(id, cv::CC_STAT_TOP),
                       stats.at<int>(id, cv::CC_STAT_WIDTH), stats.at<int>(id, cv::CC_STAT_HEIGHT));
    const PartPlanes part = FindPartPlanes(known, part_id, id, box, stats.at<int>(id, cv::CC_STAT_AREA),
                                           options, seed + static_cast<uint64_t>(id));
    if (part.planes.empty()) continue;
    for (int y = box.y; y < box.y + box.height; ++y) {
      for (int x = box.x; x < box.x + box.width; ++x) {
        if (part_id.at<int32_t>(y, x) != id || !has_return.at<uint8_t>(y, x)) continue;
        float& r = hole_range->at<float>(y, x);
        if (!(r > 0.0f) || !std::isfinite(r)) continue;
        // The reconstruction drifts with the distance it has travelled from the known ranges.
        const double travelled_m = to_border.at<float>(y, x) * part.spacing_rad * r;
        const cv::Vec2i from = source.empty() ? cv::Vec2i(-1, -1) : source.at<cv::Vec2i>(y, x);
        const double placed =
            RangeOnPlanes(part, known, hole, cv::Point(x, y), from, direction.at<cv::Vec3f>(y, x), r,
                          options.agreement_m + options.agreement_per_m * travelled_m, options);
        const double limited =
            RimPlaneRange(part, known, hole, cv::Point(x, y), direction.at<cv::Vec3f>(y, x),
                          placed > 0 ? placed : r, options.relief_m, options.tolerance);
        const double corner =
            limited > 0 ? 0.0
                        : CornerRange(part, known, hole, cv::Point(x, y), direction.at<cv::Vec3f>(y, x),
                                      placed > 0 ? placed : r, options.relief_m, options.tolerance);
        if (placed <= 0 && limited <= 0 && corner <= 0) continue;
        r = static_cast<float>(limited > 0 ? limited : corner > 0 ? corner : placed);
        ++moved;
      }
    }
  }
  return moved;
}

}  // namespace fill_internal
}  // namespace lidarshop
