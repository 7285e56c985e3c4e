// Every station of a scene scanned (docs/stations.md): what `scan` writes for a site and what the editor opens
// as a site (`lidarshop serve`, the built-in `parking_lot_stations`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/station_photos.h"
#include "lidarshop/util/options_fwd.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

// One scan per station, in order, each with the objects there (SceneAtStation) and its own scanner entry
// (pose, grid, noise, seed), named "station0", "station1", ... A scene with one "scanner" gives the one scan
// SynthesizeScan gives, under its name. Stations that see the same objects share one ray-casting scene. `progress`
// advances by rows over every station. Throws InputError for a broken mesh, OptionsError for a bad scanner.
std::vector<Scan> ScanStations(const SceneDescription& scene, Progress* progress = nullptr);

// One station of a site as `lidarshop scan --json` lists it ("stations"): its pose, objects and counts, and
// the files the command wrote for it.
struct StationScanSummary {
  int index = 0;                  // the station's index in the scene's "stations"
  std::string name;               // its scan's name: "station0", "station1", ...
  std::vector<double> position;   // the scanner's centre (x, y, z), world frame, metres
  int64_t objects = 0;            // objects of the scene at this station
  int rows = 0, columns = 0;      // the scan's grid
  int64_t rays = 0, returns = 0;  // rays cast and rays that hit something
  // The files the command wrote for this station: --split's scan, --labels' pictures, --mesh's mesh.
  std::optional<std::string> output, labels, labels_color, mesh;
};
template <>
const StructInfo& InfoOf<StationScanSummary>();

// The summary of station `index` (`station`: its scene, SceneAtStation) scanned into `scan` with `stats`; the
// file paths are left empty.
StationScanSummary SummarizeStationScan(int index, const SceneDescription& station, const Scan& scan,
                                        const ScanStats& stats);

// Wall-clock seconds of each stage of `lidarshop scan`, summed over the stations.
struct SceneScanSeconds {
  double loading = 0;         // reading or generating the scene
  double building = 0;        // the ray-casting scenes (SyntheticScanner)
  double casting = 0;         // ray casting (ScanStats::cast_seconds)
  double shading = 0;         // noise, colour, intensity, normals (ScanStats::shade_seconds)
  double scanning = 0;        // the whole scans (casting, shading and the rest)
  double meshing = 0;         // --mesh: the scans' meshes
  double photos = 0;          // --photos: rendering the station photos
  double writing = 0;         // writing_scan + writing_labels + writing_mesh
  double writing_scan = 0;    // the scan file(s)
  double writing_labels = 0;  // --labels: the label images and their colour pictures
  double writing_mesh = 0;    // --mesh: the mesh files
  double total = 0;           // the whole command
};
template <>
const StructInfo& InfoOf<SceneScanSeconds>();

// What `lidarshop scan --json` reports: the scene, the files written, the counts and where the time went.
struct SceneScanSummary {
  std::string scene;   // the scene file, built-in scene name or "random scene SEED"
  std::string output;  // the scan file (a split site: the stem of the stations' files)
  // --labels of a one-station scene: the raw label image and its colour picture (a site's are per station).
  std::optional<std::string> labels, labels_color;
  std::optional<std::string> scene_file;     // --write-scene: where the random scene's JSON went
  std::optional<int> target_label;           // the scene's target object's label, when it names one
  int64_t objects = 0;                       // objects in the scene
  int64_t triangles = 0;                     // triangles of the largest ray-casting scene built
  int rows = 0, columns = 0;                 // the (first) scan's grid
  int64_t rays = 0, returns = 0;             // over every station
  int64_t mesh_triangles = 0;                // --mesh: triangles of the meshes written (0 without)
  std::vector<StationScanSummary> stations;  // a site's stations in order; empty (absent) for one scan
  std::vector<StationPhotoSummary> photos;   // --photos: every station's photos; empty (absent) without
  int threads = 0;                           // --threads as given (0 = all cores)
  SceneScanSeconds seconds;
  double rays_per_second = 0;                   // rays / seconds.scanning
  std::optional<ScanMeshOptions> mesh_options;  // --mesh: how the meshes were made
};
template <>
const StructInfo& InfoOf<SceneScanSummary>();

}  // namespace lidarshop
