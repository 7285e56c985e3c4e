// Registration of a whole site: N stations (organized scans with rough poses) brought into one frame.
//
//   1. Overlap: which pairs of stations see the same surfaces (the share of one station's sampled points
//      within `overlap_distance_m` of the other's, at the poses given).
//   2. Coarse pass: a spanning tree from the fixed station over the overlapping pairs (largest overlap
//      first); each station is registered by point-to-plane ICP (pointset/registration.h) onto its parent,
//      already moved, so the poses come within the ICP's reach of each other.
//   3. Fine pass: point-to-plane ICP between every overlapping pair from those poses: one measured relative
//      pose scanner_a_from_scanner_b per pair (pairs whose ICP ends with less than `min_fitness` of matched
//      points are left out).
//   4. Pose graph over all those pairs (Eigen Gauss-Newton; Ceres is not part of the build): the poses X_k
//      minimizing Σ ||Log(Z_ab⁻¹ · X_a⁻¹ · X_b)||², with the fixed station's pose held, so that the errors of
//      a loop of pairs are spread over the loop instead of piling up at its end (Log = [rotation vector ·
//      `rotation_scale_m`, translation]; Grisetti et al., "A tutorial on graph-based SLAM", 2010).
//
// Frames: every pose is world_from_scanner; the fixed station keeps its own. Clouds are registered in a
// frame centred on the fixed scanner (survey coordinates stay precise in float).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "lidarshop/pointset/registration.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct SiteRegistrationOptions {
  // Points of a station used as the moving cloud of a pair, at most (a regular stride over the grid), > 0.
  int64_t max_moving_points = 60000;
  // Points of a station used as the fixed cloud (its KD-tree and normals), at most, > 0.
  int64_t max_fixed_points = 400000;
  // Two stations overlap when at least `min_overlap` of one's sampled points lie within this distance of the
  // other's at the poses given (metres, > 0): about the poses' error.
  double overlap_distance_m = 1.0;
  double min_overlap = 0.2;  // ([0, 1]) share of sampled points, see above
  // The ICP pairing distance of the coarse pass (metres, > 0): the poses' error, rotation included.
  double coarse_correspondence_m = 1.5;
  // A fine pair whose ICP matches less than this share of its moving points is left out of the graph ([0, 1]).
  double min_fitness = 0.2;
  int graph_iterations = 20;       // Gauss-Newton steps of the pose graph at most, >= 1
  double rotation_scale_m = 10.0;  // metres per radian of rotation error in the graph (> 0): a site's size
  void Check() const;              // throws OptionsError
};
template <>
const StructInfo& InfoOf<SiteRegistrationOptions>();

// The options RegisterSite takes, together: what `lidarshop register --json` reports as a site's "options"
// (the ICP's keys, then "site").
struct RegisterSiteOptions {
  IcpOptions icp;                // the pairs' ICP
  SiteRegistrationOptions site;  // the site's
};
template <>
const StructInfo& InfoOf<RegisterSiteOptions>();

// One registered pair (fine pass).
struct SitePair {
  int a = 0, b = 0;                                                 // station indices, a < b
  Eigen::Matrix4d a_from_b_measured = Eigen::Matrix4d::Identity();  // scanner_a_from_scanner_b by ICP
  double overlap = 0.0;            // step 1's share of b's sampled points near a's
  IcpResult icp;                   // the fine ICP (rms_m: point-to-plane RMS of its pairs, metres)
  bool in_graph = false;           // fitness >= min_fitness
  double graph_translation_m = 0;  // after the graph: how far the poses disagree with the measurement, metres
  double graph_rotation_deg = 0;   // and by how much they turn from it, degrees
  double seconds = 0.0;            // the pair's ICP
};

struct SiteStation {
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();  // registered
  double moved_m = 0.0;            // how far the registration moved the scanner's origin, metres
  double turned_deg = 0.0;         // and turned it, degrees
  double rms_m = 0.0;              // point-to-plane RMS over its pairs in the graph (ICP), metres
  double graph_translation_m = 0;  // the largest disagreement of its pairs with the graph, metres
  double graph_rotation_deg = 0;   // degrees
  int pairs = 0;                   // its pairs in the graph
};

struct SiteRegistration {
  std::vector<SiteStation> stations;  // one per input station, in order
  std::vector<SitePair> pairs;        // every overlapping pair
  int graph_iterations = 0;
  double seconds_overlap = 0, seconds_coarse = 0, seconds_fine = 0, seconds_graph = 0;
};

// Described as `lidarshop register --json` and Python's register_site give them: a station's
// world_from_scanner (rows), moved_m, turned_deg, pairs, rms_m and graph residuals; a pair's a, b, overlap,
// in_graph, its ICP (rms_m, fitness, correspondences, iterations, converged), graph residuals, a_from_b
// (rows) and seconds.
template <>
const StructInfo& InfoOf<SiteStation>();
template <>
const StructInfo& InfoOf<SitePair>();

// One station as `lidarshop register --json` lists it: its index, the files it came from and went to, and
// its registration (SiteStation's keys at this level).
struct SiteStationSummary {
  int index = 0;                      // in the list given to RegisterSite
  std::string input;                  // the caller's: where it was read from
  std::optional<std::string> output;  // the caller's: where it was written (none for the fixed station)
  bool fixed = false;                 // the station held
  SiteStation registration;
};
template <>
const StructInfo& InfoOf<SiteStationSummary>();

// Where a site's registration spent its time, seconds: RegisterSite's steps, and the caller's reading and
// writing of the stations and its whole run.
struct SiteRegistrationSeconds {
  double reading = 0;  // the caller's
  double overlap = 0, coarse = 0, fine = 0, graph = 0;
  double writing = 0;  // the caller's
  double total = 0;    // the caller's
};
template <>
const StructInfo& InfoOf<SiteRegistrationSeconds>();

// What `lidarshop register FIXED MOVING1 MOVING2 ... --json` reports (docs/stations.md).
struct SiteRegistrationSummary {
  std::vector<SiteStationSummary> stations;  // one per station, in order
  std::vector<SitePair> pairs;               // every overlapping pair
  int graph_iterations = 0;                  // Gauss-Newton steps of the pose graph taken
  SiteRegistrationSeconds seconds;
};
template <>
const StructInfo& InfoOf<SiteRegistrationSummary>();

// The summary of `registration`, made by RegisterSite with station `fixed` held; the file names and the
// caller's seconds are left empty.
SiteRegistrationSummary SummarizeSiteRegistration(const SiteRegistration& registration, int fixed);

// Registers `stations` (their world_from_scanner as the initial guess) with `stations[fixed]` held. Throws
// InputError when a station overlaps no other (naming it), when the stations do not form one connected
// site, or when an ICP fails (InputError of IcpPointToPlane); OptionsError for bad options or `fixed`.
SiteRegistration RegisterSite(const std::vector<Scan>& stations, int fixed, const IcpOptions& icp,
                              const SiteRegistrationOptions& options);

// The pose graph alone (step 4), for tests and callers with their own measurements: `poses` are the initial
// world_from_scanner, `pairs` the measured a_from_b_measured (only those with in_graph); poses[fixed] is
// held. Fills each pair's graph_translation_m / graph_rotation_deg; returns the iterations taken.
int OptimizePoseGraph(std::vector<Eigen::Matrix4d>* poses, std::vector<SitePair>* pairs, int fixed,
                      const SiteRegistrationOptions& options);

}  // namespace lidarshop
