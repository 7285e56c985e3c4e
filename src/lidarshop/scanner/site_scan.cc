#include "lidarshop/scanner/site_scan.h"

#include <optional>

#include <fmt/format.h>

#include "lidarshop/scanner/scanner.h"

namespace lidarshop {

std::vector<Scan> ScanStations(const SceneDescription& scene, Progress* progress) {
  if (scene.stations.empty()) return {SynthesizeScan(scene, progress)};
  const int num_stations = scene.NumStations();
  std::vector<Scan> scans;
  std::optional<SyntheticScanner> scanner;
  std::vector<bool> objects_before;
  for (int i = 0; i < num_stations; ++i) {
    std::vector<bool> objects_here;
    for (const SceneObject& object : scene.objects) objects_here.push_back(object.AtStation(i));
    const SceneDescription station = SceneAtStation(scene, i);
    // The same objects (not as many: a car that left and another that came are different scenes).
    if (!scanner || objects_here != objects_before) scanner.emplace(station);
    objects_before = std::move(objects_here);
    scans.push_back(scanner->Acquire(station.scanner, progress));
    scans.back().name = fmt::format("station{}", i);
  }
  return scans;
}

StationScanSummary SummarizeStationScan(int index, const SceneDescription& station, const Scan& scan,
                                        const ScanStats& stats) {
  StationScanSummary summary;
  summary.index = index;
  summary.name = scan.name;
  const Eigen::Vector3d& position = station.scanner.position;
  summary.position = {position.x(), position.y(), position.z()};
  summary.objects = static_cast<int64_t>(station.objects.size());
  summary.rows = scan.rows;
  summary.columns = scan.cols;
  summary.rays = stats.rays;
  summary.returns = stats.returns;
  return summary;
}

}  // namespace lidarshop
