// Fill a hole from what other stations measured (issue 31 part 3): real points first, synthesis only where no
// station saw the surface. The stations must be registered: their world_from_scanner put them in one frame.
//
//   FillFromStations(scan, hole, other_stations): the hole's cells given the surface another station measured
//   behind the removed object along the cell's own ray (marked `from_station`, not synthesized); what no
//   station saw is filled by FillScan (fill/fill.h) with those real cells as part of its boundary.
//
// The steps, for each other station B:
//   1. The removed object in B. The object's points are this scan's returns in the hole, less its rim
//      (object_margin_cells: remove's margin ring sees the background). A cell of B whose point falls on one of
//      them (B's point falls on a cell of the object in this scan's grid, within object_distance_m + the
//      noise + one footprint of that cell's range) is the object as B saw it; regions of such cells smaller than object_min_cells are dropped
//      (where a tyre touches the ground B's ground is near the object's points, and the object need not be
//      there at B). The rest grows over B's depth-continuous neighbours (object_grow_range_jump) that stay
//      inside the object's box (its points' and the grown cells' bounding box, grown by object_extent_m) and
//      that this scan did not measure outside the hole. So when the object also stands at B (the hatchback of
//      parking_lot_stations at stations 0 and 1), B's view of its far side is not taken for what is behind it.
//   2. B's grid as a mesh in the world frame: two triangles per 2 x 2 block of B's returns, dropping triangles
//      with a corner in the object, an edge across a depth discontinuity (max_range_jump_ratio) or a face seen
//      at grazing incidence (max_incidence_deg). A triangle with a corner on such a border is a rim: a ray
//      that hits it is not trusted (near an edge the nearer and the farther surface are both possible).
//   3. Each hole cell's ray (world frame) is cast into all the meshes at once (raycast/, Embree) from the
//      cell's original range + the margin (any distance when the cell had no return): the first surface
//      another station measured behind the removed object. The margin is min_margin_m + sigma_multiple × the
//      range noise σ + footprint_multiple × the ray's footprint at that range.
//   4. Free space (check_free_space): a station may not have seen a surface that lies in front of the hit (B
//      looked at that place from elsewhere and something hid it). The ray from the object to the hit is
//      sampled; every sample must be seen by some other station: its ray towards the sample went at least as
//      far (within the margin), or stopped at the object marked in step 1 while the sample is inside the
//      object's box. Otherwise the cell is left to the synthesis.
//   5. The cell's return: along its own ray, at the range where it meets the plane fitted to B's points around
//      the hit on the triangle's surface (surface_window_cells); a hit the window does not confirm (a triangle
//      across a crease) or that this ray meets more obliquely than max_incidence_deg is left to the synthesis;
//      intensity, colour and normal interpolated from B's three cells (barycentric), label from the nearest; no truth (true_range 0). No
//      synthetic noise is added: the range is B's real measurement resampled onto this scan's ray, and carries
//      B's noise (averaged over the window).
//
// What it cannot know: an object that B saw only from its far side (none of B's cells falls on this scan's
// points of it) is not marked in B, and its far side is taken as the surface behind it when it lies farther
// than the margin. A generous hole whose inner part also holds the background (beyond object_margin_cells)
// marks that background in B too: those cells are synthesized instead of taken. Surfaces that changed between
// the stations (a car that parked behind the removed one) are taken as B measured them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/options_fwd.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

struct FromStationsOptions {
  // What counts as behind the removed object, and as the same surface.
  double range_noise_sigma_m = 0.005;  // σ of the stations' range noise, metres
  double sigma_multiple = 4.0;         // the margin holds this many σ, plus min_margin_m
  double min_margin_m = 0.1;  // a surface is behind the object only this far behind it, at least, metres
  // The footprint of a ray at range d (d × the grid's angular step, radians) times this is added to the margin.
  double footprint_multiple = 2.0;
  // The other stations' meshes.
  double max_range_jump_ratio = 0.1;  // an edge whose ranges differ by more (a fraction of the nearer) is cut
  double max_incidence_deg = 85.0;    // a triangle seen more obliquely than this (either scanner) is not used
  // The removed object in the other stations (step 1 of the header).
  int object_margin_cells = 2;      // the hole's rim this wide is background, not the object, cells
  double object_distance_m = 0.03;  // a station's point this near the object's (+ noise, footprint) is it, m
  int object_min_cells = 30;        // regions of such cells smaller are dropped, cells
  double object_grow_range_jump = 0.03;  // largest relative range step between grown neighbours
  double object_extent_m = 1.0;          // the growth stays inside the object's box grown by this, metres
  // Step 5: the range from a plane fitted to the other station's points of the (2k + 1)² cells around the hit
  // on the same surface (their noise averaged: at grazing incidence one point's noise across the surface
  // becomes several times its size along this scan's ray); 0 = the triangle's interpolation alone.
  int surface_window_cells = 2;
  // Free space between the object and the hit (step 4).
  bool check_free_space = true;
  double free_space_step = 0.01;  // samples along the ray every this fraction of the range (at least 5 cm)
  // The cells no station saw.
  bool fill_rest = true;  // false: they are left without a return
  FillOptions fill;       // their fill

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<FromStationsOptions>();

// The options `fill --stations` and `remove --stations` used, as their --json's "options" holds them: the
// command's own options with the stations' under "from_stations" (whose `fill` is the command's fill).
struct FillWithStationsOptions {
  FillOptions fill;
  FromStationsOptions from_stations;
};
template <>
const StructInfo& InfoOf<FillWithStationsOptions>();
struct RemoveWithStationsOptions {
  RemoveOptions remove;
  FromStationsOptions from_stations;
};
template <>
const StructInfo& InfoOf<RemoveWithStationsOptions>();

// One other station of a fill from stations as the result lists it: which scan it is and what it gave.
struct FromStationsSource {
  int64_t station = 0;             // 1 + its index in other_stations: its tag in from_station
  std::string file;                // the file it was read from (set by the caller that read it)
  int64_t scan = 0;                // its index in that file (set by the caller that read it)
  std::string name;                // its scan's name
  int64_t from_station_cells = 0;  // hole cells filled from it (cells_per_station)
  int64_t object_cells = 0;  // cells of the removed object seen in it (object_cells; 0 for an empty hole)
};
template <>
const StructInfo& InfoOf<FromStationsSource>();

// Its JSON (InfoOf): the synthesis's numbers (FillResult's keys, when it ran) with the hole's own counts and
// warnings in place of the synthesis's, then the counts of the cells taken from the stations.
struct FromStationsResult {
  Scan scan;  // the input with the hole filled; every cell outside the hole is a copy
  // CV_8U rows x cols: 1 + k = filled from other_stations[k] (the same as scan.from_station), 0 = not.
  cv::Mat from_station;
  cv::Mat synthesized;  // CV_8U rows x cols: 255 = a hole cell the fill invented (no station saw it)
  int64_t hole_cells = 0;
  int64_t from_station_cells = 0;          // non-zero cells of from_station
  std::vector<int64_t> cells_per_station;  // per other station: the cells filled from it
  int64_t synthesized_cells = 0;           // non-zero cells of synthesized
  int64_t no_return_cells = 0;             // hole cells left without a return
  // Cells whose first hit was a rim triangle, a surface the window around it does not confirm, or a surface
  // this scan's ray meets more obliquely than max_incidence_deg (left to the synthesis).
  int64_t rim_cells = 0;
  int64_t not_free_cells = 0;  // cells whose hit failed the free-space check (left to the synthesis)
  std::vector<cv::Mat> object_in_station;  // per other station, CV_8U: 255 = the removed object seen there
  std::vector<int64_t> object_cells;       // per other station: non-zero cells of object_in_station
  bool filled_rest = false;  // FillScan ran (fill below holds its result; otherwise it is empty)
  FillResult fill;
  double stations_seconds = 0, fill_seconds = 0;  // wall seconds: the cast from the stations, the synthesis
  std::vector<std::string> warnings;  // the fill's warnings and what looks wrong, one sentence each
  // Per other station, in order: cells_per_station and object_cells with the station's name; file and scan
  // are the caller's to set.
  std::vector<FromStationsSource> stations;
};
template <>
const StructInfo& InfoOf<FromStationsResult>();

// Fills `hole` (CV_8U rows x cols of `scan`, non-zero = fill) from `other_stations` first, then by FillScan.
// Throws InputError when the mask's size differs, when a station has no grid (an unorganized cloud), and as
// FillScan; OptionsError for bad options. `progress` advances once per other station and once per 4096 hole
// cells cast.
FromStationsResult FillFromStations(const Scan& scan, const cv::Mat& hole,
                                    const std::vector<Scan>& other_stations,
                                    const FromStationsOptions& options = {}, Progress* progress = nullptr);

// Remove an object (fill/remove.h: the cut from strokes, its cells grown by remove.margin_cells) and fill its
// hole from `other_stations` first (FillFromStations with `from`; its object_margin_cells and fill are taken
// from `remove`). With remove.keep_object, `behind` holds the filled cells behind the object's own cells.
struct RemoveFromStationsResult {
  SegmentResult cut;
  cv::Mat hole;  // CV_8U 255 = the object's cells (and enclosed no-return cells) grown by the margin
  FromStationsResult filled;          // filled.scan: the scan without the object
  Scan behind;                        // keep_object: as RemoveResult::behind; empty otherwise
  std::vector<std::string> warnings;  // the cut's then the fill's
};
template <>
const StructInfo& InfoOf<RemoveFromStationsResult>();
RemoveFromStationsResult RemoveObjectFromStations(const Scan& scan, const cv::Mat& strokes,
                                                  const std::vector<Scan>& other_stations,
                                                  const RemoveOptions& remove, FromStationsOptions from = {},
                                                  Progress* progress = nullptr);

}  // namespace lidarshop
