// Regular facades: what a window row hides, from the windows beside it and above it.
//
// A greedy patch fill continues what the hole's rim shows one patch at a time. Behind a van it runs a window's
// glass down past its sill, or a pane into the wall beside a window whose edge it never sees: no patch knows
// where a window ends. A facade repeats along its length at one window pitch and up it at one storey, and the
// scan shows both. So, after the patch fill, for each part of the hole:
//   1. the planes around it (surface_planes.h), the upright ones only (walls and facades), each refitted by
//      RANSAC to the known cells on it near the hole (the band around a thin hole leaves a facade's tilt a few
//      degrees loose: 0.2 m at one pitch);
//   2. its pitch along the plane's horizontal u and its storey up it, v: known cells on the plane (within
//      `relief_m`) are compared, in colour and relief, with the cells that see the same point of the plane
//      shifted by D; the score 1 − mean squared difference / (2 · variance) is taken every 5 cm from
//      `min_period_m` to `max_period_m` and refined to half a cell's footprint around the pitch chosen: the best
//      score peak that reaches `min_score` and stands 0.5 above the valley before it (a plain wall scores about
//      the same at every shift), or the shortest whole fraction of it (1/2 .. 1/4) that still does (a door
//      spoils some shifts more than others, so the best may be two pitches);
//   3. a hole cell whose patch source lies on the plane and does not face up (the patch fill decided the cell
//      shows the facade: not the ground at its foot, not the sky) is copied instead from the medoid, in colour
//      and relief, of the cells that see its ray's point of the plane shifted by ±1, ±2, … pitches and storeys
//      (the nearest `max_translates` each way, 5 per axis at most) and of its patch source: the windows outvote
//      the one door a shift lands on;
//   4. unless the hole cuts an exception there: the first known cell above the cell in its column, and the one
//      0.25 m to a side of it, both differ from what their own translates agree on (a door's top where the other
//      bays show a window's). Then that cell is copied down the column: an opening cut by the hole runs on
//      behind it, as a door reaches the ground;
//   5. each such cell's range is that of its ray to the plane moved by its source's relief (a pane 0.15 m back).
// Shifts are made on the plane, in metres, not in cells: the scan's grid is angular, so one pitch spans fewer
// columns far to the side than straight ahead, and a shift by a fixed number of cells would not bring a
// window onto a window there.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/fill/surface_planes.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct FacadeLatticeOptions {
  bool enabled = true;        // false = the patch fill's sources as they are
  double min_period_m = 0.8;  // shortest pitch sought, metres (> 0)
  double max_period_m = 8;    // longest pitch sought, metres (> min_period_m)
  double min_score = 0.6;     // a plane repeats when a peak of the shift score reaches this, (0, 1]
  int max_translates = 4;     // shifts tried each way along each axis, pitches or storeys (>= 1)
  double relief_m = 0.3;      // a cell is on a plane within this distance (window recesses), metres (> 0)
  int max_samples = 3000;     // known cells compared per shift at most (>= 100)
  void Check() const;         // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<FacadeLatticeOptions>();

namespace fill_internal {

struct FacadeLatticeReport {
  // Per repeating plane and part of the hole: the pitch along the plane's horizontal and the one up it (a
  // storey), metres, 0 where it does not repeat.
  std::vector<double> pitches_m, storeys_m;
  int64_t cells = 0;  // hole cells whose source the lattice changed
};

// Replaces the sources (`source`, CV_32SC2 (row, col), (−1, −1) = none) of the hole cells whose source lies
// on a repeating plane, as described above. `relief_range` (CV_32F) receives, for each cell the lattice
// decided (changed or kept), the range of step 5, 0 elsewhere: copied range gradients come from cells a pitch
// or a storey away, whose rays meet the plane at other angles, and would drift over a storey's height, where
// these ranges do not. `range`, `known_valid` and `direction` as for SnapToPlanes; `guide` CV_32FC(1 or 3) the
// fill's colour or intensity (grey levels); `grid` the scan's angular grid (GridOf in scan/scan.h; one that
// does not match the scan's size or is not monotonic turns the lattice off).
FacadeLatticeReport RefineSourcesByLattice(const cv::Mat& range, const cv::Mat& known_valid,
                                           const cv::Mat& direction, const cv::Mat& guide,
                                           const cv::Mat& hole, const ScanGrid& grid,
                                           const FillPlaneOptions& planes,
                                           const FacadeLatticeOptions& options, uint64_t seed,
                                           cv::Mat* source, cv::Mat* relief_range);

}  // namespace fill_internal
}  // namespace lidarshop
