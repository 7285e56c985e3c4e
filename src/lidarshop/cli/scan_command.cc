// lidarshop scan SCENE.json -o OUT.ptx|.ply [--labels L.png] [--mesh M.ply] [--seed N] [--threads N]
// [--stats]
//
// Synthesizes a scan of a scene description (scanner/scene.h, docs/scene-format.md) with the synthetic
// scanner and writes it; --stats prints one JSON object on stdout with the counts and the seconds of each
// stage.
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scan_mesh.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {

int RunScan(int argc, char** argv) {
  CLI::App app("Synthesize an organized scan of a scene description (JSON) with the synthetic scanner.",
               "scan");
  std::string scene_path, output_path, labels_path, mesh_path;
  uint64_t seed = 0;
  std::optional<int> rows, columns;
  int threads = 0;
  bool stats = false, quiet = false;
  double mesh_jump_ratio = ScanMeshOptions().max_range_jump_ratio;
  app.add_option("scene", scene_path, "scene description (.json, see docs/scene-format.md)")->required();
  app.add_option("-o,--output", output_path,
                 "output scan: .ptx, .ply, .e57, .pcd (or the points alone: .las, .xyz, .pts)")
      ->required();
  app.add_option(
      "--labels", labels_path,
      "per-ray object labels as a 16-bit single-channel PNG (65535 where the ray returned nothing)");
  app.add_option("--mesh", mesh_path, "triangle mesh of the scan (.ply): adjacent returns joined");
  app.add_option("--mesh-jump", mesh_jump_ratio,
                 "with --mesh: drop edges whose ranges differ by more than this fraction of the nearer range")
      ->capture_default_str();
  AddSeedOption(app, &seed, "noise seed (overrides the scene's scanner.seed)");
  app.add_option("--rows", rows, "points per strip (overrides scanner.rows)");
  app.add_option("--columns", columns, "strips (overrides scanner.columns)");
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->capture_default_str();
  app.add_flag("--stats", stats, "print one JSON object with counts and seconds per stage on stdout");
  AddQuietFlag(app, &quiet);
  return RunCommand(app, argc, argv, [&]() {
    CheckOption(threads >= 0, fmt::format("--threads must be >= 0, got {}", threads));
    CheckOutputPath(output_path, {scene_path});
    if (!labels_path.empty()) CheckOutputPath(labels_path, {scene_path, output_path});
    if (!mesh_path.empty()) CheckOutputPath(mesh_path, {scene_path, output_path, labels_path});
    const ThreadLimit thread_limit(threads);
    Timer total;
    Timer stage;
    SceneDescription scene = LoadScene(scene_path);
    if (app.count("--seed") > 0) scene.scanner.seed = seed;
    if (rows) scene.scanner.rows = *rows;
    if (columns) scene.scanner.columns = *columns;
    scene.scanner.Check();
    ScanMeshOptions mesh_options;
    mesh_options.max_range_jump_ratio = mesh_jump_ratio;
    mesh_options.Check();
    const double loading_seconds = stage.Seconds();

    stage.Restart();
    const SyntheticScanner scanner(scene);
    const double building_seconds = stage.Seconds();

    stage.Restart();
    ScanStats scan_stats;
    Scan scan;
    {
      auto progress = Progress::ForTerminal("scanning", scene.scanner.rows, quiet);
      scan = scanner.Acquire(scene.scanner, progress.get(), &scan_stats);
      progress->Finish();
    }
    const double scanning_seconds = stage.Seconds();

    stage.Restart();
    WriteScanFile(output_path, {scan});
    const double writing_scan_seconds = stage.Seconds();
    double writing_labels_seconds = 0, meshing_seconds = 0, writing_mesh_seconds = 0;
    int64_t mesh_triangles = 0;
    if (!labels_path.empty()) {
      stage.Restart();
      WriteImage(labels_path, LabelImage16(scan));
      writing_labels_seconds = stage.Seconds();
    }
    if (!mesh_path.empty()) {
      stage.Restart();
      const TriangleMesh mesh = ScanToMesh(scan, mesh_options);
      mesh_triangles = static_cast<int64_t>(mesh.triangles.size());
      meshing_seconds = stage.Seconds();
      stage.Restart();
      WriteMesh(mesh_path, mesh);
      writing_mesh_seconds = stage.Seconds();
    }
    if (stats) {
      nlohmann::ordered_json json;
      json["scene"] = scene_path;
      json["output"] = output_path;
      json["objects"] = scene.objects.size();
      json["triangles"] = scanner.num_triangles();
      json["rows"] = scan.rows;
      json["columns"] = scan.cols;
      json["rays"] = scan_stats.rays;
      json["returns"] = scan_stats.returns;
      json["mesh_triangles"] = mesh_triangles;
      json["threads"] = threads;
      json["seconds"] = {{"loading", loading_seconds},
                         {"building", building_seconds},
                         {"casting", scan_stats.cast_seconds},
                         {"shading", scan_stats.shade_seconds},
                         {"scanning", scanning_seconds},
                         {"meshing", meshing_seconds},
                         {"writing", writing_scan_seconds + writing_labels_seconds + writing_mesh_seconds},
                         {"writing_scan", writing_scan_seconds},
                         {"writing_labels", writing_labels_seconds},
                         {"writing_mesh", writing_mesh_seconds},
                         {"total", total.Seconds()}};
      json["rays_per_second"] = scan_stats.rays / std::max(1e-9, scanning_seconds);
      fmt::print("{}\n", json.dump());
    }
    return 0;
  });
}

}  // namespace lidarshop::cli
