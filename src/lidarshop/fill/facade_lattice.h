// Regular facades: what a window row hides, from the windows beside it.
//
// A greedy patch fill continues what the hole's rim shows one patch at a time. Behind a van it runs a window's
// glass down past its sill, or a pane into the wall beside a window whose edge it never sees: no patch knows
// where a window ends. A facade repeats along its length at one window pitch, and the scan shows the pitch.
// So, after the patch fill, for each part of the hole:
//   1. the planes around it (surface_planes.h), the near-vertical ones only (walls and facades);
//   2. a plane's pitch: known cells on it (within `relief_m`) are compared, in colour and relief, with the
//      cells that see the same point of the plane shifted by D along the plane's horizontal; the score
//      1 − mean squared difference / (2 · variance) is taken for D from `min_period_m` to `max_period_m` in
//      steps of half a cell's footprint; when the best reaches `min_score`, the pitch is the shortest whole
//      fraction of it (1/2, 1/3, 1/4, within 5 %) that scores `min_score` too (a door or a car spoils some
//      shifts more than others, so the best may be two pitches);
//   3. a hole cell whose patch source lies on a periodic plane (so the patch fill decided the cell shows that
//      plane: not the wall in front of it, not the sky) is copied instead from the cell that sees its ray's
//      point of the plane shifted by k pitches, k = ±1, ±2, … ±`max_translates`: of the first three shifts
//      whose cell is known and on the plane, the one that agrees best with the others (a car before one of
//      them is outvoted), the nearest on ties.
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
  double min_score = 0.6;     // a plane repeats when its best shift scores at least this, (0, 1]
  int max_translates = 4;     // shifts tried on each side, pitches (>= 1)
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
  std::vector<double> pitches_m, floors_m;
  int64_t cells = 0;  // hole cells given a source by the lattice
};

// Replaces the sources (`source`, CV_32SC2 (row, col), (−1, −1) = none) of the hole cells whose source lies
// on a periodic plane, as described above; `relief_range` (CV_32F) receives, for each such cell, the range
// along its ray to the plane moved by its source's relief (its offset from the plane), 0 elsewhere: copied
// range gradients come from cells a pitch or a storey away, whose rays meet the plane at other angles, and
// would drift over a storey's height, where these ranges do not. `range`, `known_valid` and `direction` as for SnapToPlanes;
// `guide` CV_32FC(1 or 3) the fill's colour or intensity (grey levels); `grid` the scan's angular grid (when
// empty, one is read off the ray directions; a grid that is not monotonic turns the lattice off).
FacadeLatticeReport RefineSourcesByLattice(const cv::Mat& range, const cv::Mat& known_valid,
                                           const cv::Mat& direction, const cv::Mat& guide,
                                           const cv::Mat& hole, const ScanGrid& grid,
                                           const FillPlaneOptions& planes,
                                           const FacadeLatticeOptions& options, uint64_t seed,
                                           cv::Mat* source, cv::Mat* relief_range);

}  // namespace fill_internal
}  // namespace lidarshop
