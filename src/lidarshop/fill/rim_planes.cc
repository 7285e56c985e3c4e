#include "lidarshop/fill/rim_planes.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Core>

namespace lidarshop::fill_internal {
namespace {

// The plane known cell (y, x) lies on (facing its way, within kReliefStepM; the nearest), or −1.
int CellPlane(const PartPlanes& part, const KnownCells& known, int y, int x) {
  Eigen::Vector3f normal;
  if (!known.Usable(y, x) || !CellNormal(known, y, x, &normal)) return -1;
  const Eigen::Vector3f q = known.PointAt(y, x);
  int best = -1;
  double best_distance = kReliefStepM;
  for (size_t k = 0; k < part.planes.size(); ++k) {
    const double d = std::abs(part.planes[k].SignedDistance(q));
    if (d > best_distance || std::abs(normal.cast<double>().dot(part.planes[k].normal)) < kFacingNormal)
      continue;
    best = static_cast<int>(k);
    best_distance = d;
  }
  return best;
}

}  // namespace

bool PairPlane(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole, int y, int x, int pair,
               int max_gap, double relief_m, int* plane, double* offset_m, int* gap) {
  constexpr std::array<std::array<int, 2>, 4> kSteps{{{0, -1}, {0, 1}, {-1, 0}, {1, 0}}};
  const int limit = max_gap < 0 ? std::max(hole.rows, hole.cols) : max_gap;
  std::array<cv::Point, 2> end;
  *gap = 1;
  for (size_t side = 0; side < 2; ++side) {
    const auto& step = kSteps[2 * static_cast<size_t>(pair) + side];
    int yy = y, xx = x;
    do {
      yy += step[0];
      xx += step[1];
      ++*gap;
    } while (*gap <= limit && yy >= 0 && xx >= 0 && yy < hole.rows && xx < hole.cols &&
             hole.at<uint8_t>(yy, xx));
    end[side] = cv::Point(xx, yy);
  }
  *gap -= 2;  // the steps onto the two known cells
  if (*gap > limit - 1) return false;
  std::array<Eigen::Vector3f, 2> normal;
  if (!known.Usable(end[0].y, end[0].x) || !known.Usable(end[1].y, end[1].x) ||
      !CellNormal(known, end[0].y, end[0].x, &normal[0]) ||
      !CellNormal(known, end[1].y, end[1].x, &normal[1]))
    return false;
  int best = -1;
  double best_offset = 0;
  for (size_t k = 0; k < part.planes.size(); ++k) {
    const SeenPlane& p = part.planes[k];
    const double a = p.SignedDistance(known.PointAt(end[0].y, end[0].x));
    const double b = p.SignedDistance(known.PointAt(end[1].y, end[1].x));
    if (std::abs(normal[0].cast<double>().dot(p.normal)) < kFacingNormal ||
        std::abs(normal[1].cast<double>().dot(p.normal)) < kFacingNormal || std::abs(a) > relief_m ||
        std::abs(b) > relief_m || std::abs(a - b) > kReliefStepM)
      continue;
    if (best < 0 || std::abs(a + b) < std::abs(2 * best_offset)) {
      best = static_cast<int>(k);
      best_offset = 0.5 * (a + b);
    }
  }
  if (best < 0) return false;
  *plane = best;
  *offset_m = best_offset;
  return true;
}

double RimPlaneRange(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole,
                     const cv::Point& cell, const cv::Vec3f& dir, double r, double relief_m,
                     double tolerance) {
  const Eigen::Vector3d ray(dir[0], dir[1], dir[2]);
  for (int pair = 0; pair < 2; ++pair) {
    int k = -1, gap = 0;
    double offset = 0;
    if (!PairPlane(part, known, hole, cell.y, cell.x, pair, -1, relief_m, &k, &offset, &gap)) continue;
    const SeenPlane& p = part.planes[static_cast<size_t>(k)];
    const double off_plane = p.SignedDistance((ray * r).cast<float>()) - offset;
    if (std::abs(off_plane) <= relief_m) continue;
    const double facing = p.normal.dot(ray);
    if (std::abs(facing) < 1e-6) continue;
    const double along = (offset - p.offset_m) / facing;
    if (!(along > 0) || (off_plane > 0 && along > (1 + tolerance) * r)) continue;
    // The known cells across: an opening in the wall, or a surface before it, seen beside the cell.
    bool seen_off = false;
    const int dy = pair == 0 ? 1 : 0, dx = pair == 0 ? 0 : 1;
    for (int sign : {-1, 1}) {
      if (off_plane > 0 && pair == 0) break;  // below a wall the ground stands before it: no evidence
      int yy = cell.y, xx = cell.x;
      do {
        yy += sign * dy;
        xx += sign * dx;
      } while (yy >= 0 && xx >= 0 && yy < hole.rows && xx < hole.cols && hole.at<uint8_t>(yy, xx));
      if (!known.Usable(yy, xx)) continue;
      const double across = p.SignedDistance(known.PointAt(yy, xx)) - offset;
      if (std::abs(across) > relief_m && (across > 0) == (off_plane > 0)) seen_off = true;
    }
    if (!seen_off) return along;
  }
  return 0;
}

double CornerRange(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole,
                   const cv::Point& cell, const cv::Vec3f& dir, double r, double relief_m, double tolerance) {
  std::array<int, 2> plane{-1, -1};
  for (int side = 0; side < 2; ++side) {
    const int step = side == 0 ? -1 : 1;
    int x = cell.x;
    do {
      x += step;
    } while (x >= 0 && x < hole.cols && hole.at<uint8_t>(cell.y, x));
    plane[side] = CellPlane(part, known, cell.y, x);
    if (plane[side] < 0) return 0;
  }
  if (plane[0] == plane[1]) return 0;
  const Meeting meeting = part.At(static_cast<size_t>(plane[0]), static_cast<size_t>(plane[1]));
  if (meeting == Meeting::kNone) return 0;
  const Eigen::Vector3d ray(dir[0], dir[1], dir[2]);
  std::array<double, 2> along{};
  for (int side = 0; side < 2; ++side) {
    const SeenPlane& p = part.planes[static_cast<size_t>(plane[side])];
    const double facing = p.normal.dot(ray);
    along[side] = std::abs(facing) < 1e-6 ? -1.0 : -p.offset_m / facing;
  }
  if (!(along[0] > 0) || !(along[1] > 0)) return 0;
  const double placed =
      meeting == Meeting::kConcave ? std::min(along[0], along[1]) : std::max(along[0], along[1]);
  const double off = std::abs(placed - r);
  return off > relief_m && off <= tolerance * r ? placed : 0;
}

}  // namespace lidarshop::fill_internal
