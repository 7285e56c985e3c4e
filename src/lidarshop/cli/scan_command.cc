// lidarshop scan SCENE.json|BUILTIN|--random SEED -o OUT.ptx|.ply|.e57 [--write-scene S.json] [--labels L.png]
// [--mesh M.ply] [--seed N] [--threads N] [--json FILE|-] [--stats] [--photos sphere|cube [--photo-size PX]]
//
// Synthesizes a scan of a scene description (scanner/scene.h, docs/scene-format.md), of a built-in scene
// (parking_lot, ...: the scenes of `demo --scene`) or of the random scene of a seed (scanner/random_scene.h;
// --write-scene saves its JSON) with the synthetic scanner and writes it; --json writes one JSON object with
// the counts and the seconds of each stage (--stats = --json -). Scanner flags (--rows, --seed, ...) override
// the scene's "scanner" entries. --photos (E57 output only) writes the station's own photos into the file's
// images2D (scanner/station_photos.h).
//
// A site (scene "stations", docs/stations.md): every station is scanned with the objects there (at_stations)
// and written into OUT in order (E57: one data3D per station named station0, station1, ... with its pose;
// PTX: the scans in order), or with --split into OUT's stem + _N; --labels L.png and --mesh M.ply write L_N.png
// and M_N.ply per station.
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/render.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/random_scene.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/scanner/station_photos.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
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

// The name of station i's data3D entry / PTX scan in a site's file.
std::string StationName(int station) { return fmt::format("station{}", station); }

// OUT.ext -> OUT_N.ext: station N's file of a split site, labels or mesh.
std::string StationPath(const std::string& path, int station) {
  const std::filesystem::path p(path);
  return (p.parent_path() / fmt::format("{}_{}{}", p.stem().string(), station, p.extension().string()))
      .string();
}

// Refuses, before any scanning, outputs that would overwrite each other or an input, and a site of several
// stations into a format that holds one scan (PCD) without --split.
void CheckStationOutputs(bool site, bool split, int num_stations, const std::string& output_path,
                         const std::string& labels_path, const std::string& mesh_path,
                         const std::string& scene_path) {
  if (!site) return;
  if (!split && num_stations > 1) {
    const ScanFormatInfo* format = FindScanFormat(FileExtension(output_path));
    if (format != nullptr && format->scans == ScansPerFile::kOne) {
      throw OptionsError(
          fmt::format("{} holds one scan and the scene has {} stations: give --split (one file "
                      "per station) or write {}",
                      output_path, num_stations, FormatNamesWhere([](const ScanFormatInfo& f) {
                        return f.write && f.scans == ScansPerFile::kSeveral;
                      })));
    }
  }
  std::vector<std::string> written = {scene_path};
  auto add = [&](const std::string& path) {
    CheckOutputPath(path, written);
    written.push_back(path);
  };
  if (!split) add(output_path);
  for (int i = 0; i < num_stations; ++i) {
    if (split) add(StationPath(output_path, i));
    if (!labels_path.empty()) {
      add(StationPath(labels_path, i));
      add(ColorLabelsPath(StationPath(labels_path, i)));  // L_N_color.png beside L_N.png
    }
    if (!mesh_path.empty()) add(StationPath(mesh_path, i));
  }
}

}  // namespace

int RunScan(int argc, char** argv) {
  CLI::App app("Synthesize an organized scan of a scene description (JSON) with the synthetic scanner.",
               "scan");
  std::string scene_path, output_path, labels_path, mesh_path, json_path, write_scene_path;
  std::optional<uint64_t> random_seed;
  int threads = 0;
  bool stats = false, quiet = false, split = false;
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
  app.add_flag(
      "--split", split,
      "a site (scene \"stations\"): one file per station, OUT's stem + _N (site_0.ptx, site_1.ptx, ...) "
      "instead of every station in OUT (E57: one data3D per station, PTX: the scans in order)");
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
          PrintWarnings(scene.warnings);
        }
        // One scene per station (a one-station scene is its own station 0): the flags override every
        // station's scanner.
        const int num_stations = scene.NumStations();
        // A site: several stations, or --split (one file per station, also of a one-station scene).
        const bool site = !scene.stations.empty() || split;
        CheckStationOutputs(site, split, num_stations, output_path, labels_path, mesh_path, scene_path);
        std::vector<SceneDescription> station_scenes;
        for (int i = 0; i < num_stations; ++i) {
          station_scenes.push_back(site ? SceneAtStation(scene, i) : scene);
          StructFromJson(InfoOf<ScannerOptions>(), binder.Given(), &station_scenes.back().scanner);
          station_scenes.back().scanner.Check();
        }
        const double loading_seconds = stage.Seconds();

        double building_seconds = 0, scanning_seconds = 0, photo_seconds = 0;
        ScanStats scan_stats;
        int64_t triangles = 0;
        std::vector<Scan> scans(num_stations);
        std::vector<std::vector<StationPhoto>> photos(num_stations);
        std::vector<ScanStats> station_stats(num_stations);
        std::optional<SyntheticScanner> scanner;
        for (int i = 0; i < num_stations; ++i) {
          const SceneDescription& station = station_scenes[i];
          // Stations that see the same objects share one ray-casting scene (the same objects, not as many:
          // a car that left and another that came are two different scenes).
          auto objects_at = [&](int k) {
            std::vector<bool> at;
            for (const SceneObject& object : scene.objects) at.push_back(!site || object.AtStation(k));
            return at;
          };
          const bool same_objects = i > 0 && objects_at(i) == objects_at(i - 1);
          if (!same_objects) {
            stage.Restart();
            scanner.emplace(station);
            building_seconds += stage.Seconds();
            triangles = std::max(triangles, scanner->num_triangles());
          }
          stage.Restart();
          {
            auto progress =
                Progress::ForTerminal(site ? fmt::format("scanning station {}", i) : std::string("scanning"),
                                      station.scanner.rows, quiet);
            scans[i] = scanner->Acquire(station.scanner, progress.get(), &station_stats[i]);
            progress->Finish();
          }
          if (site) scans[i].name = StationName(i);
          scanning_seconds += stage.Seconds();
          scan_stats.rays += station_stats[i].rays;
          scan_stats.returns += station_stats[i].returns;
          scan_stats.cast_seconds += station_stats[i].cast_seconds;
          scan_stats.shade_seconds += station_stats[i].shade_seconds;
          if (!photos_kind.empty()) {
            stage.Restart();
            StationPhotoOptions photo_options;
            photo_options.kind = photos_kind == "cube" ? StationPhotoKind::kCube : StationPhotoKind::kSphere;
            photo_options.size_px = photo_size_px;
            photo_options.seed = station.scanner.seed;
            photos[i] = RenderStationPhotos(station, station.scanner, photo_options);
            photo_seconds += stage.Seconds();
          }
        }

        // Where each station goes: all into OUT, or (--split) OUT's stem + _N; the same for labels and mesh.
        auto station_path = [&](const std::string& path, int i) {
          return site ? StationPath(path, i) : path;
        };
        stage.Restart();
        if (!site || !split) {
          std::vector<E57Image> images;
          for (int i = 0; i < num_stations; ++i) {
            const std::vector<E57Image> station_images = StationPhotosToE57(photos[i], i);
            images.insert(images.end(), station_images.begin(), station_images.end());
          }
          if (photos_kind.empty()) {
            WriteScanFile(output_path, scans);
          } else {
            WriteE57(output_path, scans, images, E57WriteOptions{});
          }
        } else {
          for (int i = 0; i < num_stations; ++i) {
            if (photos_kind.empty()) {
              WriteScanFile(station_path(output_path, i), {scans[i]});
            } else {
              WriteE57(station_path(output_path, i), {scans[i]}, StationPhotosToE57(photos[i], 0),
                       E57WriteOptions{});
            }
          }
        }
        const double writing_scan_seconds = stage.Seconds();
        double writing_labels_seconds = 0, meshing_seconds = 0, writing_mesh_seconds = 0;
        int64_t mesh_triangles = 0;
        for (int i = 0; i < num_stations; ++i) {
          const Scan& scan = scans[i];
          if (!labels_path.empty()) {
            stage.Restart();
            WriteImage(station_path(labels_path, i), LabelImage16(scan));
            // One pixel per ray like the raw image, so the two overlay; the legend names the objects.
            RenderOptions colors;
            colors.channel = RenderChannel::kLabels;
            colors.legend = true;
            colors.label_names = ObjectNamesByLabel(scene);
            WriteImage(site ? ColorLabelsPath(StationPath(labels_path, i)) : labels_color_path,
                       RenderScan(scan, colors).image);
            writing_labels_seconds += stage.Seconds();
          }
          if (!mesh_path.empty()) {
            stage.Restart();
            const TriangleMesh mesh = ScanToMesh(scan, mesh_options);
            mesh_triangles += static_cast<int64_t>(mesh.triangles.size());
            meshing_seconds += stage.Seconds();
            stage.Restart();
            WriteMesh(station_path(mesh_path, i), mesh);
            writing_mesh_seconds += stage.Seconds();
          }
        }
        const Scan& scan = scans[0];
        size_t num_photos = 0;
        for (const auto& station_photos : photos) num_photos += station_photos.size();
        if (!json_path.empty()) {
          SceneScanSummary summary;
          summary.scene = scene_path;
          summary.output = output_path;
          if (!labels_path.empty() && !site) {  // a site's are per station, under "stations"
            summary.labels = labels_path;
            summary.labels_color = labels_color_path;
          }
          if (!write_scene_path.empty()) summary.scene_file = write_scene_path;
          if (scene.target_label >= 0) summary.target_label = scene.target_label;
          summary.objects = static_cast<int64_t>(scene.objects.size());
          summary.triangles = triangles;
          summary.rows = scan.rows;
          summary.columns = scan.cols;
          summary.rays = scan_stats.rays;
          summary.returns = scan_stats.returns;
          summary.mesh_triangles = mesh_triangles;
          for (int i = 0; site && i < num_stations; ++i) {
            StationScanSummary station =
                SummarizeStationScan(i, station_scenes[i], scans[i], station_stats[i]);
            if (split) station.output = station_path(output_path, i);
            if (!labels_path.empty()) {
              station.labels = station_path(labels_path, i);
              station.labels_color = ColorLabelsPath(station_path(labels_path, i));
            }
            if (!mesh_path.empty()) station.mesh = station_path(mesh_path, i);
            summary.stations.push_back(std::move(station));
          }
          for (int i = 0; i < num_stations; ++i) {
            for (const StationPhoto& photo : photos[i])
              summary.photos.push_back(
                  SummarizeStationPhoto(photo, site ? std::optional<int>(i) : std::nullopt));
          }
          summary.threads = threads;
          summary.seconds = {.loading = loading_seconds,
                             .building = building_seconds,
                             .casting = scan_stats.cast_seconds,
                             .shading = scan_stats.shade_seconds,
                             .scanning = scanning_seconds,
                             .meshing = meshing_seconds,
                             .photos = photo_seconds,
                             .writing = writing_scan_seconds + writing_labels_seconds + writing_mesh_seconds,
                             .writing_scan = writing_scan_seconds,
                             .writing_labels = writing_labels_seconds,
                             .writing_mesh = writing_mesh_seconds,
                             .total = total.Seconds()};
          summary.rays_per_second = scan_stats.rays / std::max(1e-9, scanning_seconds);
          if (!mesh_path.empty()) summary.mesh_options = mesh_options;
          WriteJsonOutput(json_path, CommandJson(ToJson(station_scenes[0].scanner), ToJson(summary)));
        }
        Summarize(fmt::format("{}{} x {} scan{}, {} returns of {} rays{} -> {}",
                              site ? fmt::format("{} stations: ", num_stations) : std::string(), scan.rows,
                              scan.cols, site ? "s" : "", scan_stats.returns, scan_stats.rays,
                              num_photos == 0 ? "" : fmt::format(", {} photo(s)", num_photos),
                              site && split ? station_path(output_path, 0) + " ..." : output_path));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
