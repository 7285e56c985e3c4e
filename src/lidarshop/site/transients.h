// What moved between the stations of a site: a point one station measured is transient when the rays of
// another station, which should have seen it, passed through where it was and hit something farther away
// (free-space evidence; Cyclone's moving-object filter and the "peopleRemover" literature do the same). The
// stations must be registered: their world_from_scanner put them in one world frame.
//
//   FindTransients(stations): per station, the cells whose point another station saw through, and why;
//   CleanStations(stations):  each station with those points removed and their holes filled.
//
// The test, for a point p of station A (world) and another station B: p in B's frame is at range d along a
// direction that falls on a cell of B's grid. B saw through p when every cell of that cell's neighbourhood
// (neighbourhood_cells on each side) returned, and returned farther than d + margin, where the margin covers
// the range noise and the footprint of B's rays at d (a ray beside an edge, or at grazing incidence on the
// ground, hits nearer and farther than its neighbours; asking all of them to be farther keeps those static).
// B saw p itself when its cell returned within the margin of d: that point is confirmed static. Transient
// regions smaller than min_region_cells are dropped (single cells of noise); the rest grow by grow_cells over
// depth-continuous neighbours that no station confirmed, so that the rims of a person are removed with it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/fill/fill.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

struct TransientOptions {
  double range_noise_sigma_m = 0.005;  // σ of the stations' range noise, metres
  double sigma_multiple = 4.0;         // the margin holds this many σ, plus min_margin_m
  double min_margin_m = 0.1;           // seen through only this far behind the point at least, metres
  // The footprint of a ray at range d (d × the grid's angular step) times this is added to the margin.
  double footprint_multiple = 2.0;
  int neighbourhood_cells = 1;        // cells on each side of the ray's cell that must all see farther
  int min_region_cells = 12;          // transient regions (8-connected, in A's grid) smaller are kept
  int grow_cells = 4;                 // then grown this far over depth-continuous, unconfirmed neighbours
  double grow_max_range_jump = 0.03;  // largest relative range step between grown neighbours

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<TransientOptions>();

struct StationTransients {
  cv::Mat transient;  // CV_8U rows x cols: 255 = a transient point
  // CV_8U: why: 1 + the index of the first station whose rays passed through the point; 0 = not transient.
  cv::Mat seen_through_by;
  cv::Mat confirmed;               // CV_8U: 255 = another station measured the same point (static)
  int64_t transient_cells = 0;     // non-zero cells of `transient`
  int64_t confirmed_cells = 0;     // non-zero cells of `confirmed`
  int64_t seen_through_cells = 0;  // cells with free-space evidence before the region filter and growth
};

struct TransientResult {
  std::vector<StationTransients> stations;  // one per input station, in order
};

// Throws InputError when fewer than two stations are given or a station has no grid (an unorganized cloud).
TransientResult FindTransients(const std::vector<Scan>& stations, const TransientOptions& options = {},
                               Progress* progress = nullptr);

struct CleanOptions {
  TransientOptions transients;
  FillOptions fill;        // the fill of the removed points' holes
  int margin_cells = 1;    // the removed cells are grown by this before filling (mixed pixels at rims)
  bool fill_holes = true;  // false: removed points become cells without a return
  // The holes are filled first from what the other stations measured behind the removed points
  // (site/from_stations.h: its defaults, with transients.range_noise_sigma_m and margin_cells), and only the
  // rest is synthesized by `fill`; false: every hole cell is synthesized.
  bool from_stations = true;

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<CleanOptions>();

struct CleanResult {
  std::vector<Scan> stations;         // the cleaned stations, in order
  TransientResult transients;         // what was found
  std::vector<int64_t> filled_cells;  // per station: cells the fill gave a synthesized return
  // Per station: hole cells given another station's measurement (their Scan::from_station holds 1 + the
  // index, in the list given to CleanStations, of the station that measured them).
  std::vector<int64_t> from_station_cells;
  std::vector<std::string> warnings;  // the fills' warnings, naming the station
};

// Removes every station's transient points and fills their holes: first with what the other stations measured
// behind them (FillFromStations, marked from_station, not synthesized), then the rest by FillScan
// (synthesized, marked).
CleanResult CleanStations(const std::vector<Scan>& stations, const CleanOptions& options = {},
                          Progress* progress = nullptr);

// One station of a clean as `lidarshop clean --json` lists it: what was removed and filled, and where the
// station came from and went to (the caller's: left empty by SummarizeClean).
struct CleanStationSummary {
  std::string file;          // the caller's: the file it was read from (FILE or FILE#N)
  uint64_t scan = 0;         // the caller's: its scan in that file, from 0
  std::string output;        // the caller's: the file it was written to
  int64_t returns = 0;       // cells with a return before the clean
  int64_t removed = 0;       // StationTransients::transient_cells
  int64_t seen_through = 0;  // StationTransients::seen_through_cells
  int64_t confirmed = 0;     // StationTransients::confirmed_cells
  int64_t filled = 0;        // CleanResult::filled_cells
  int64_t from_station = 0;  // CleanResult::from_station_cells
  std::string removed_mask;  // the caller's: the picture of the removed cells written, "" for none
};
template <>
const StructInfo& InfoOf<CleanStationSummary>();

// What `lidarshop clean --json` reports.
struct CleanSummary {
  std::vector<CleanStationSummary> stations;  // one per station, in order
  int64_t removed = 0;                        // transient cells removed, every station
  std::vector<std::string> warnings;          // CleanResult::warnings
};
template <>
const StructInfo& InfoOf<CleanSummary>();

// The summary of `result`, the clean of `stations` (as given to CleanStations); the caller's fields left
// empty.
CleanSummary SummarizeClean(const std::vector<Scan>& stations, const CleanResult& result);

}  // namespace lidarshop
