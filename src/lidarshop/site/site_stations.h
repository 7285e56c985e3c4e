// The stations of a site as a list a user reads (docs/stations.md): where each stands and where it looks, its
// grid and its returns. What `lidarshop info` prints for a file of several scans, the editor's station list
// (src/server/routes_stations.cc) and the checks of station indices a caller gives.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// The heading of a scanner, degrees in (-180, 180]: its forward axis (+y) turned about the world z, positive
// to the left (counter-clockwise seen from above), as the yaw of a scene's rotate_deg. 0 = looking along +y.
double HeadingDeg(const Eigen::Matrix4d& world_from_scanner);

struct StationSummary {
  int index = 0;
  std::string name;                                      // the scan's name ("station1"; may be empty)
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // the scanner's origin in the world, metres
  double heading_deg = 0;                                // HeadingDeg
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  int rows = 0, cols = 0;
  int64_t returns = 0;     // valid cells
  bool organized = false;  // the scan has a grid (stations without one cannot be cleaned)
};

// One summary per scan, in order (index = position in `stations`).
std::vector<StationSummary> SummarizeStations(const std::vector<Scan>& stations);
StationSummary SummarizeStation(const Scan& station, int index);

// {"index", "name", "position_m": [x, y, z], "heading_deg", "world_from_scanner_column_major": [16],
//  "rows", "cols", "returns", "organized"}.
nlohmann::ordered_json StationSummaryJson(const StationSummary& station);

// Station indices a caller chose (`field` names them in errors): each in [0, num_stations), none twice.
// Throws OptionsError naming the field, the index and the number of stations.
void CheckStationIndices(const std::vector<int>& indices, int num_stations, const std::string& field);

}  // namespace lidarshop
