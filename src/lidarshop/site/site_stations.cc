#include "lidarshop/site/site_stations.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

double HeadingDeg(const Eigen::Matrix4d& world_from_scanner) {
  // The scanner's +y in the world is the rotation's second column; yaw = atan2(-x, y) (rotate_deg's yaw turns
  // +y towards -x).
  return std::atan2(-world_from_scanner(0, 1), world_from_scanner(1, 1)) * 180.0 / M_PI;
}

StationSummary SummarizeStation(const Scan& station, int index) {
  StationSummary summary;
  summary.index = index;
  summary.name = station.name;
  summary.world_from_scanner = station.world_from_scanner;
  summary.position_m = station.world_from_scanner.topRightCorner<3, 1>();
  summary.heading_deg = HeadingDeg(station.world_from_scanner);
  summary.rows = station.rows;
  summary.cols = station.cols;
  summary.returns = station.CountValid();
  summary.organized = station.rows > 1 && station.cols > 1 && HasRayDirections(station);
  return summary;
}

std::vector<StationSummary> SummarizeStations(const std::vector<Scan>& stations) {
  std::vector<StationSummary> summaries;
  for (size_t i = 0; i < stations.size(); ++i) summaries.push_back(SummarizeStation(stations[i], int(i)));
  return summaries;
}

nlohmann::ordered_json StationSummaryJson(const StationSummary& station) {
  const Eigen::Matrix4d& m = station.world_from_scanner;
  return {{"index", station.index},
          {"name", station.name},
          {"position_m", {station.position_m.x(), station.position_m.y(), station.position_m.z()}},
          {"heading_deg", station.heading_deg},
          {"world_from_scanner_column_major", std::vector<double>(m.data(), m.data() + 16)},
          {"rows", station.rows},
          {"cols", station.cols},
          {"returns", station.returns},
          {"organized", station.organized}};
}

void CheckStationIndices(const std::vector<int>& indices, int num_stations, const std::string& field) {
  std::vector<int> seen;
  for (const int index : indices) {
    if (index < 0 || index >= num_stations) {
      throw OptionsFieldError(field, fmt::format("station {} is out of range: the site has {} station(s), "
                                                 "numbered from 0",
                                                 index, num_stations));
    }
    if (std::find(seen.begin(), seen.end(), index) != seen.end()) {
      throw OptionsFieldError(field, fmt::format("station {} is given twice", index));
    }
    seen.push_back(index);
  }
}

}  // namespace lidarshop
