// lidarshop scan SCENE.json|BUILTIN|--random SEED -o OUT.ptx|.ply|.e57 [--write-scene S.json] [--labels L.png]
// [--mesh M.ply] [--seed N] [--threads N] [--json FILE|-] [--stats] [--photos sphere|cube [--photo-size PX]]
//
// Synthesizes a scan of a scene description (scanner/scene.h, docs/scene-format.md), of a built-in scene
// (parking_lot, ...: the scenes of `demo --scene`) or of the random scene of a seed (scanner/random_scene.h;
// --write-scene saves its JSON) with the synthetic scanner and writes it; --json writes one JSON object with
// the counts and the seconds of each stage (--stats = --json -). Scanner flags (--rows, --seed, ...) override
// the scene's "scanner" entries. --photos (E57 output only) writes the station's own photos into the file's
// images2D (scanner/station_photos.h).
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/builtin_scenes.h"
#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/render.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/random_scene.h"
#include "lidarshop/scanner/scan_mesh.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/station_photos.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {
namespace {

// L.png -> L_color.png, beside the raw label image.
std::string ColorLabelsPath(const std::string& labels_path) {
  const std::filesystem::path path(labels_path);
  return (path.parent_path() / (path.stem().string() + "_color.png")).string();
}

}  // namespace

int RunScan(int argc, char** argv) {
  CLI::App app("Synthesize an organized scan of a scene description (JSON) with the synthetic scanner.",
               "scan");
  std::string scene_path, output_path, labels_path, mesh_path, json_path, write_scene_path;
  std::optional<uint64_t> random_seed;
  int threads = 0;
  bool stats = false, quiet = false;
  // The scanner flags override the scene file's "scanner": only the ones given are applied.
  ScannerOptions scanner_overrides;
  ScanMeshOptions mesh_options;
  OptionBinder binder(app);
  app.add_option(
      "scene", scene_path,
      "scene description (.json, see docs/scene-format.md) or a built-in scene:" + BuiltinSceneNames());
  app.add_option("--random", random_seed,
                 "instead of SCENE: the random street or indoor scene of this seed (scanner/random_scene.h; "
                 "400 x 300 cells, the target object named by the scene's target_label)");
  app.add_option("--write-scene", write_scene_path, "with --random: also write the scene's JSON here");
  app.add_option("-o,--output", output_path,
                 "output scan: .ptx, .ply, .e57, .pcd (or the points alone: .las, .xyz, .pts)")
      ->required();
  app.add_option(
      "--labels", labels_path,
      "per-ray object labels as a 16-bit single-channel PNG (65535 where the ray returned nothing); their "
      "colour picture with the objects' names goes beside it (L.png -> L_color.png)");
  app.add_option("--mesh", mesh_path, "triangle mesh of the scan (.ply): adjacent returns joined");
  AddJsonOption(app, &json_path);
  app.add_flag("--stats", stats, "= --json -: counts and seconds per stage as one JSON object on stdout");
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->capture_default_str();
  binder.Bind(&scanner_overrides, {.group = "Scanner (default: the scene's \"scanner\")", .overrides = true});
  binder.Bind(&mesh_options,
              {.keys = {"max_range_jump_ratio"}, .flags = {{"max_range_jump_ratio", "--mesh-jump"}}});
  std::string photos_kind;
  int photo_size_px = 512;
  app.add_option("--photos", photos_kind,
                 "E57 output: also write the station's photos (images2D) from a camera 0.15 m above the "
                 "scanner, photo 0 at exposure 1, the others with a gain within ±30 % drawn from the seed: "
                 "sphere = one spherical panorama, cube = six 90° pinhole faces")
      ->check(CLI::IsMember({"sphere", "cube"}));
  app.add_option("--photo-size", photo_size_px,
                 "--photos: the panorama's height (its width is twice) or a cube face's side, pixels")
      ->capture_default_str();
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        if (stats && json_path.empty()) json_path = "-";
        CheckOption(threads >= 0, fmt::format("--threads must be >= 0, got {}", threads));
        CheckOption(scene_path.empty() != !random_seed.has_value(),
                    "give exactly one of SCENE and --random SEED");
        CheckOption(write_scene_path.empty() || random_seed.has_value(), "--write-scene needs --random SEED");
        if (random_seed) scene_path = fmt::format("random scene {}", *random_seed);
        if (!write_scene_path.empty())
          CheckOutputPath(write_scene_path, {output_path, labels_path, mesh_path});
        CheckOutputPath(output_path, {scene_path});
        if (!labels_path.empty()) CheckOutputPath(labels_path, {scene_path, output_path});
        const std::string labels_color_path = labels_path.empty() ? "" : ColorLabelsPath(labels_path);
        if (!labels_path.empty()) CheckOutputPath(labels_color_path, {scene_path, output_path, labels_path});
        if (!mesh_path.empty()) CheckOutputPath(mesh_path, {scene_path, output_path, labels_path});
        CheckOutputFile("--json", json_path, {}, {scene_path, output_path, labels_path, mesh_path});
        binder.Validate(mesh_options);
        if (!photos_kind.empty()) {
          const ScanFormatInfo* format = FindScanFormat(FileExtension(output_path));
          if (format == nullptr || !format->images)
            throw OptionsError(fmt::format(
                "--photos needs an output that holds photos ({}): {} cannot hold them",
                FormatNamesWhere([](const ScanFormatInfo& f) { return f.images && f.write; }), output_path));
        }
        if (photos_kind.empty() && app.count("--photo-size"))
          throw OptionsError("--photo-size is for --photos");
        const ThreadLimit thread_limit(threads);
        Timer total;
        Timer stage;
        SceneDescription scene;
        if (random_seed) {
          const std::string text = RandomSceneJson(*random_seed);
          scene = ParseScene(text, scene_path, "");
          if (!write_scene_path.empty()) {
            WriteFileAtomically(write_scene_path, [&](std::ostream& out) { out << text << "\n"; });
          }
        } else {
          scene = LoadSceneOrBuiltin(scene_path);
        }
        StructFromJson(InfoOf<ScannerOptions>(), binder.Given(), &scene.scanner);
        scene.scanner.Check();
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

        std::vector<StationPhoto> photos;
        double photo_seconds = 0;
        if (!photos_kind.empty()) {
          stage.Restart();
          StationPhotoOptions photo_options;
          photo_options.kind = photos_kind == "cube" ? StationPhotoKind::kCube : StationPhotoKind::kSphere;
          photo_options.size_px = photo_size_px;
          photo_options.seed = scene.scanner.seed;
          photos = RenderStationPhotos(scene, scene.scanner, photo_options);
          photo_seconds = stage.Seconds();
        }

        stage.Restart();
        if (photos.empty()) {
          WriteScanFile(output_path, {scan});
        } else {
          WriteE57(output_path, {scan}, StationPhotosToE57(photos), E57WriteOptions{});
        }
        const double writing_scan_seconds = stage.Seconds();
        double writing_labels_seconds = 0, meshing_seconds = 0, writing_mesh_seconds = 0;
        int64_t mesh_triangles = 0;
        if (!labels_path.empty()) {
          stage.Restart();
          WriteImage(labels_path, LabelImage16(scan));
          // One pixel per ray like the raw image, so the two overlay; the legend names the objects.
          RenderOptions colors;
          colors.channel = RenderChannel::kLabels;
          colors.legend = true;
          colors.label_names = ObjectNamesByLabel(scene);
          WriteImage(labels_color_path, RenderScan(scan, colors).image);
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
        if (!json_path.empty()) {
          nlohmann::ordered_json json;
          json["scene"] = scene_path;
          json["output"] = output_path;
          if (!labels_path.empty()) {
            json["labels"] = labels_path;
            json["labels_color"] = labels_color_path;
          }
          if (!write_scene_path.empty()) json["scene_file"] = write_scene_path;
          if (scene.target_label >= 0) json["target_label"] = scene.target_label;
          json["objects"] = scene.objects.size();
          json["triangles"] = scanner.num_triangles();
          json["rows"] = scan.rows;
          json["columns"] = scan.cols;
          json["rays"] = scan_stats.rays;
          json["returns"] = scan_stats.returns;
          json["mesh_triangles"] = mesh_triangles;
          if (!photos.empty()) {
            nlohmann::ordered_json list = nlohmann::ordered_json::array();
            for (const StationPhoto& photo : photos) {
              list.push_back({{"name", photo.name},
                              {"model", CameraModelName(photo.camera.model)},
                              {"width_px", photo.image.cols},
                              {"height_px", photo.image.rows},
                              {"gain", photo.gain}});
            }
            json["photos"] = list;
          }
          json["threads"] = threads;
          json["seconds"] = {
              {"loading", loading_seconds},
              {"building", building_seconds},
              {"casting", scan_stats.cast_seconds},
              {"shading", scan_stats.shade_seconds},
              {"scanning", scanning_seconds},
              {"meshing", meshing_seconds},
              {"photos", photo_seconds},
              {"writing", writing_scan_seconds + writing_labels_seconds + writing_mesh_seconds},
              {"writing_scan", writing_scan_seconds},
              {"writing_labels", writing_labels_seconds},
              {"writing_mesh", writing_mesh_seconds},
              {"total", total.Seconds()}};
          json["rays_per_second"] = scan_stats.rays / std::max(1e-9, scanning_seconds);
          if (!mesh_path.empty()) json["mesh_options"] = ToJson(mesh_options);
          WriteJsonOutput(json_path, CommandJson(ToJson(scene.scanner), json));
        }
        Summarize(fmt::format(
            "{} x {} scan, {} returns of {} rays{} -> {}", scan.rows, scan.cols, scan_stats.returns,
            scan_stats.rays, photos.empty() ? "" : fmt::format(", {} photo(s)", photos.size()), output_path));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
