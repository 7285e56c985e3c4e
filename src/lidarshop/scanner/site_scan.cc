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

}  // namespace lidarshop
