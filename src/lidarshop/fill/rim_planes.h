// The planes of one part of the hole as surface_planes.cc finds them, and the rules that put a hole cell on
// the planes its row's (or column's) nearest known cells lie on (rim_planes.cc). Internal to fill/.
#pragma once

#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/fill/surface_planes.h"

namespace lidarshop::fill_internal {

// cos 25°: the source of a copied relief faces the plane's way (a window pane, not the face of a kerb).
inline constexpr double kFacingNormal = 0.906;

// Two reliefs on one plane differ when they are this far apart (a window recess is 0.1-0.3 m deep; the
// floating share counts points 0.1 m off the surface).
inline constexpr double kReliefStepM = 0.05;

// How two planes meet (surface_planes.h, step 4).
enum class Meeting { kNone, kConcave, kConvex };

// The planes of one part of the hole, how each pair meets, and the part's ray spacing.
struct PartPlanes {
  std::vector<SeenPlane> planes;
  std::vector<Meeting> meeting;  // planes² (row-major)
  double spacing_rad = 0;
  Meeting At(size_t a, size_t b) const { return meeting[a * planes.size() + b]; }
};

// The plane the two nearest known cells of hole cell (y, x) along one axis (`pair` 0: left and right, 1:
// above and below) both lie on, facing its way, within relief_m of it and at one relief (within
// kReliefStepM): its index `*plane` and that relief `*offset_m`. Only when at most `max_gap` cells lie
// between them (a negative max_gap: any gap); `*gap` receives that count.
bool PairPlane(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole, int y, int x, int pair,
               int max_gap, double relief_m, int* plane, double* offset_m, int* gap);

// The range hole cell `cell` (ray `dir`, placed at range `r`) takes when r lies more than relief_m off the
// plane its two nearest known cells left and right (or above and below), however far apart, both lie on at
// one relief; 0 when it does not. Between two cells of one wall the ray meets that wall: a surface behind it
// cannot be seen there (random seed 87, a gap 20 cells wide between two cells of a fence's board: the board
// 0.35 m behind it, copied from beside the hole, floated), unless a known cell across (above or below, or left
// and right) lies behind it too: the wall has an opening there (a gap between two buildings). A surface in
// front of it would have to be hidden whole by the removed object in that row, which no fill can know (seed
// 30, a membrane from a person 5 m away to the wall behind him: 19.3 → 9.2 % floating), unless the known cells
// left and right of a column pair stand before the plane too (something before the wall reaches into the hole
// from the side; the cells above and below a row pair are no evidence: below a wall the ground stands before
// it), and only within `tolerance` of r (a plane met at grazing incidence is far off).
double RimPlaneRange(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole,
                     const cv::Point& cell, const cv::Vec3f& dir, double r, double relief_m,
                     double tolerance);

// The range hole cell `cell` (ray `dir`, placed at range `r`) takes when the nearest known cells left and
// right of it lie on two planes that meet — in a concave crease, where the ray stops at the nearer (two walls
// of an inner corner, a wall on the ground seen obliquely), or a convex edge, at the farther — and r lies
// more than relief_m from that and within `tolerance` × r of it; 0 otherwise. A row is one elevation: between
// its two ends the crease or the edge is the surface, and a reconstruction that drifted off it floats.
double CornerRange(const PartPlanes& part, const KnownCells& known, const cv::Mat& hole,
                   const cv::Point& cell, const cv::Vec3f& dir, double r, double relief_m, double tolerance);

}  // namespace lidarshop::fill_internal
