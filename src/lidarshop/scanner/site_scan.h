// Every station of a scene scanned (docs/stations.md): what `scan` writes for a site and what the editor opens
// as a site (`lidarshop serve`, the built-in `parking_lot_stations`).
#pragma once

#include <vector>

#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

// One scan per station, in order, each with the objects there (SceneAtStation) and its own scanner entry
// (pose, grid, noise, seed), named "station0", "station1", ... A scene with one "scanner" gives the one scan
// SynthesizeScan gives, under its name. Stations that see the same objects share one ray-casting scene. `progress`
// advances by rows over every station. Throws InputError for a broken mesh, OptionsError for a bad scanner.
std::vector<Scan> ScanStations(const SceneDescription& scene, Progress* progress = nullptr);

}  // namespace lidarshop
