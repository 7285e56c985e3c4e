// Planes around a hole, and the fill's ranges placed on them (the hidden crease behind a car).
//
// The Poisson reconstruction of the copied gradients drifts over a large hole: behind a van the facade and
// the ground come out right near the hole's border, but the hidden wall–ground crease ends up tens of
// centimetres off, and the points there float. Built surroundings are mostly planes, and the planes seen
// around the hole continue behind the object. So, after the Poisson step, each filled cell is moved onto one:
//   1. planes are found one after another among the known cells in a band around each connected part of
//      the hole by a RANSAC that counts only cells facing the plane's way (their grid normals; not the plane
//      through a staircase's nosings), refitted to the largest grid-connected part of those cells and then to
//      every band cell on it that faces its way, kept when a quarter of them lie in the band's outer half (not
//      what the cut left of the object itself on the hole's rim) and, below min_share of the band, when they
//      reach past the hole on two opposite sides (a kerb's face);
//   2. a cell's candidates are the planes whose intersection with its ray lies within `tolerance` × the
//      reconstructed range; with none, the cell keeps the reconstructed range;
//   3. a cell in a narrow gap (a post's column) between two known cells on one plane at one relief goes onto
//      that plane at that relief; otherwise the cell goes onto the plane its patch source lies on (facing its
//      way, within `relief_m`), at the source's signed distance from it — relief is copied, not flattened (a
//      window recess stays a recess) — unless the known cells left and right of it, or above and below, agree
//      on another relief on that plane (patches are matched on range gradients, blind to a recess's depth);
//      a cell copied from no plane goes onto the nearest candidate only when the reconstruction agrees with it
//      (`agreement_m`, growing with the distance from the hole's border);
//   4. then the order the surroundings show: two planes whose seen parts each lie in front of the other meet
//      in a concave crease (a wall standing on the ground: the ray stops at the nearer), two whose parts each
//      lie behind the other in a convex edge (a kerb's top and face: the ray passes the nearer plane's
//      extension and stops at the farther).
// A plane is unbounded, which is wrong beyond a wall's end; the tolerance around the reconstruction, which
// already knows where the wall ends (its depth jump is copied and cut), keeps the plane out there.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct FillPlaneOptions {
  bool enabled = true;  // false = the reconstructed ranges as they are
  // Width of the band of known cells around each part of the hole in which planes are sought; 0 = a quarter of
  // the part's equivalent diameter (2·sqrt(cells/π)/4), at least 8 and at most 80 cells.
  int band_cells = 0;
  // RANSAC inlier distance: inlier_m + inlier_per_m × the band's median range (range noise and the scanner's
  // footprint grow with range).
  double inlier_m = 0.02;       // metres, > 0
  double inlier_per_m = 0.002;  // metres per metre of range, >= 0
  int max_planes = 6;           // planes per part of the hole, >= 1
  // A plane is kept when it holds at least this share of the band's cells (and at least 50 cells).
  double min_share = 0.05;  // (0, 1)
  // A plane is a candidate for a cell when its intersection with the cell's ray is within this fraction of the
  // reconstructed range (the reconstruction of a car-sized hole drifts by a tenth of the range).
  double tolerance = 0.2;  // (0, 1)
  // The patch source's plane is preferred over the one nearest the reconstruction only when it lies within
  // agreement_m + agreement_per_m × t of the reconstruction, t the cell's distance from the hole's border
  // (cells × ray spacing × range, metres): near the border the known ranges pin the reconstruction down.
  double agreement_m = 0.05;     // metres, >= 0
  double agreement_per_m = 1.0;  // metres per metre from the border, >= 0
  double relief_m = 0.3;  // largest copied offset from a plane, metres, >= 0 (0 = flatten onto the plane)
  void Check() const;     // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<FillPlaneOptions>();

namespace fill_internal {

// The known cells of the scan: ranges (0 without a return), which are usable, and the rays.
struct KnownCells {
  const cv::Mat& range;      // CV_32F
  const cv::Mat& valid;      // CV_8U, outside the hole with a return
  const cv::Mat& direction;  // CV_32FC3
  bool Usable(int y, int x) const {
    return y >= 0 && x >= 0 && y < range.rows && x < range.cols && valid.at<uint8_t>(y, x);
  }
  Eigen::Vector3f PointAt(int y, int x) const {
    const cv::Vec3f d = direction.at<cv::Vec3f>(y, x);
    const float r = range.at<float>(y, x);
    return {d[0] * r, d[1] * r, d[2] * r};
  }
};

// n · x + offset_m = 0 with offset_m > 0: the scanner (the origin) is on the positive side.
struct SeenPlane {
  Eigen::Vector3d normal;
  double offset_m = 0;
  std::vector<Eigen::Vector3f> seen;  // its inliers in the band
  double SignedDistance(const Eigen::Vector3f& x) const { return normal.dot(x.cast<double>()) + offset_m; }
};

// The unit normal at a known cell from its known neighbours two cells away on each side (a wider base than
// one cell, so that range noise tilts it by a few degrees only); false where they are missing.
bool CellNormal(const KnownCells& known, int y, int x, Eigen::Vector3f* normal);

// cos 60°: a plane whose normal is within 30° of the horizontal stands upright (a wall, a facade).
constexpr double kUprightNormalZ = 0.5;

// Step 1 above: the planes among the known cells in a band around one part of the hole (the cells of
// `part_id` (CV_32S connected-component labels over the scan) equal to `id`, `box` its bounding box, of
// `part_cells` cells); `threshold_m` receives the RANSAC inlier distance used. An upright plane parallel to an
// earlier one and within relief_m of it (a facade's panes) is left out.
std::vector<SeenPlane> BandPlanes(const KnownCells& known, const cv::Mat& part_id, int id,
                                  const cv::Rect& box, int part_cells, const FillPlaneOptions& options,
                                  uint64_t seed, double* threshold_m);

// Moves the ranges of the hole cells with a return (`has_return`, CV_8U) onto the planes around the hole, as
// described above. `range` (CV_32F, the scan's ranges outside the hole, 0 without a return) and `known_valid`
// (CV_8U) describe the known cells; `direction` is the scan's CV_32FC3 unit ray directions; `source`
// (CV_32SC2, may be empty) the cell each hole cell was copied from; `hole_range` (CV_32F) holds the
// reconstructed ranges and is updated. Returns the number of cells moved.
int64_t SnapToPlanes(const cv::Mat& range, const cv::Mat& known_valid, const cv::Mat& direction,
                     const cv::Mat& hole, const cv::Mat& has_return, const cv::Mat& source,
                     const FillPlaneOptions& options, uint64_t seed, cv::Mat* hole_range);

}  // namespace fill_internal
}  // namespace lidarshop
