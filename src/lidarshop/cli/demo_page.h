// The summary `lidarshop demo` writes (summary.json, --json), described (util/options.h), and its page
// (index.html): the template data/demo/index.html.mustache, compiled into the executable (this folder's
// CMakeLists.txt), filled with the summary's numbers.
//
// The summary is the demo's own composition of the library's results (VerifyResult, SweepResult, MaskScores,
// FillResult and FillMetrics, FromStationsResult) with the objects they are about; summary.json has always
// been written with its keys sorted (DemoSummaryJson), whatever the order here.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop::cli {

// Step 1: the scan.
struct DemoScanSummary {
  int rows = 0, cols = 0;
  int64_t valid = 0;      // cells with a return
  int64_t triangles = 0;  // triangles of the scanned scene
};

// Step 2: one object at one pose (verify.json holds the list).
struct DemoVerifyEntry {
  std::string object;  // the scene object's name
  std::string pose;    // "true", "1 m towards the scanner" or "1 m away from the scanner"
  double consistency = std::numeric_limits<double>::quiet_NaN();  // NaN (null) when nothing is comparable
  int64_t comparable_pairs = 0;
  double confidence = 0;                                       // [0, 1]
  double icp_cost = std::numeric_limits<double>::quiet_NaN();  // metres, NaN (null) when no inlier pair
  double inlier_fraction = 0;
};

// Step 2b: a detection of the sweep.
struct DemoSweepDetection {
  double x = 0, y = 0;  // metres, world position of the model origin
  double yaw_deg = 0;
  double consistency = 0, confidence = 0;
};

struct DemoSweepSummary {
  std::string model;                           // the scene object whose mesh is swept
  std::vector<double> true_position;           // metres, its world x, y
  uint64_t poses = 0;                          // poses verified: the grid's and the refinement's
  std::vector<DemoSweepDetection> detections;  // by decreasing confidence
};

// Step 3: the cut-out object, scored against the scanner's labels.
struct DemoSegmentSummary {
  std::string object;
  int32_t label = 0;  // its label
  double iou = 0, precision = 0, recall = 0;
  int64_t object_cells = 0;
  double seconds = 0;  // wall seconds of the segmentation
};

// Step 4: the object removed and its hole filled, scored against the scene scanned without it.
struct DemoRemoveSummary {
  std::string object;
  int64_t hole_cells = 0;
  int64_t synthesized_points = 0;  // hole cells given a return
  int64_t no_return_cells = 0;
  double range_rmse_mm = 0, range_mae_mm = 0;
  double within_20mm = 0;      // share of compared cells within 20 mm
  double floating_points = 0;  // share of synthesized points floating (FillMetrics::floating_share)
  double return_accuracy = 0;  // share of hole cells whose return / no-return matches the truth
  double color_psnr_db = 0;
  double seconds = 0;  // wall seconds of the fill
};

// Step 4b: the object removed from station 0 of the scene's site, filled from station 2 first.
struct DemoStationsSummary {
  std::string object;
  std::string site;  // the built-in site
  int64_t hole_cells = 0, from_station_cells = 0, synthesized_cells = 0, no_return_cells = 0;
  double from_station_rmse_mm = 0;  // range error of the cells taken from station 2 (0 when none)
  double range_rmse_mm = 0;         // of the whole fill
  double floating_points = 0;
  double seconds = 0;  // wall seconds: the cast from the station and the synthesis
};

// Wall seconds of each step (the steps a scene has).
struct DemoSeconds {
  double load = 0, scan = 0, write = 0, verify = 0;
  std::optional<double> sweep, segment, remove, stations;
};

struct DemoSummary {
  std::string scene;  // the scene's name
  DemoScanSummary scan;
  std::vector<DemoVerifyEntry> verify;
  std::optional<DemoSweepSummary> sweep;      // scenes with a "demo"."sweep"
  std::optional<DemoSegmentSummary> segment;  // scenes with an object to cut out
  std::optional<DemoRemoveSummary> remove;
  std::optional<DemoStationsSummary> stations;  // scenes with a site holding the object
  DemoSeconds seconds;
};

// summary.json's content: ToJson(summary) with its keys sorted, as it has always been written.
nlohmann::json DemoSummaryJson(const DemoSummary& summary);

// Every file the demo writes (index.html aside), with what it holds, for the steps `summary` has results of.
std::vector<std::pair<std::string, std::string>> DemoFiles(const DemoSummary& summary);

// index.html for the scene `scene_name` from the demo's summary.
std::string DemoPage(const std::string& scene_name, const DemoSummary& summary);

}  // namespace lidarshop::cli

namespace lidarshop {
template <>
const StructInfo& InfoOf<cli::DemoScanSummary>();
template <>
const StructInfo& InfoOf<cli::DemoVerifyEntry>();
template <>
const StructInfo& InfoOf<cli::DemoSweepDetection>();
template <>
const StructInfo& InfoOf<cli::DemoSweepSummary>();
template <>
const StructInfo& InfoOf<cli::DemoSegmentSummary>();
template <>
const StructInfo& InfoOf<cli::DemoRemoveSummary>();
template <>
const StructInfo& InfoOf<cli::DemoStationsSummary>();
template <>
const StructInfo& InfoOf<cli::DemoSeconds>();
template <>
const StructInfo& InfoOf<cli::DemoSummary>();
}  // namespace lidarshop
