// Hough plane detection (the 3-D Hough transform with the "ball" accumulator of Borrmann et al. 2011: normal
// directions on the upper hemisphere in rings of equal elevation step, each ring with azimuth cells in
// proportion to its circumference, and distance cells along each normal). Every sampled point votes for every
// plane through it; the fullest cell is a plane, its points (within half a distance cell, on the full cloud)
// are removed, and voting starts again for the next plane.
#pragma once

#include <cstdint>
#include <vector>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct HoughPlaneOptions {
  double angle_step_deg = 2.0;    // normal direction resolution, degrees, in (0, 30]
  double distance_step_m = 0.05;  // plane offset resolution, metres, > 0
  int64_t max_voters = 20000;     // points sampled to vote (all when fewer), >= 3
  int max_planes = 1;             // >= 1
  int64_t min_inliers = 100;      // stop when the next plane has fewer points on the full cloud, >= 3
  uint64_t seed = 1;              // the sample of voters
  void Check() const;             // throws OptionsError
};
template <>
const StructInfo& InfoOf<HoughPlaneOptions>();

// Planes as PlaneFit (inliers within half a distance cell of the cell's plane, then refitted by least
// squares; `iterations` = the votes of the cell). Throws InputError on empty or degenerate clouds.
std::vector<PlaneFit> DetectPlanesHough(const PointCloud& cloud, const HoughPlaneOptions& options);

}  // namespace lidarshop
