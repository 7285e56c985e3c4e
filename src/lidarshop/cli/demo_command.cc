// `lidarshop demo`: the main job on a built-in scene, end to end, with every result in one folder.
//
//   1. scan      synthesize the scene (ground truth included): scan.ptx, scan.e57, labels.png, pictures of
//                every channel, range.exr, top_view.png (a second viewpoint)
//   2. verify    every standing object at its true pose, and at wrong poses, against the scan: verify.json;
//                in the parking lot, a sweep of one car's model over the lot: sweep_*.png, sweep.csv
//   3. segment   cut one object out from two automatic strokes, compared with the true labels: segment_*.png
//   4. remove    fill behind the cut-out object (gradient-domain fill), scored against the scene scanned
//                again without the object: removed.e57, remove_*.png
//   4b. stations (parking_lot) the same object removed from station 0 of the built-in site
//                parking_lot_stations with the real points station 2 measured behind it (the car had left
//                there), only the rest synthesized (site/from_stations.h): stations_*.png, stations.e57
//   5. summary   summary.json and index.html, which shows everything on one page
//
// The steps only call the library; the scene is compiled into the executable (builtin_scenes.h) and says what
// the steps do with it (its "demo" key: the object to cut out, the sweep, the site); the page is a template
// (data/demo/index.html.mustache, demo_page.h).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/demo_page.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/render_view.h"
#include "lidarshop/render/strokes.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_eval.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/util/timer.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct DemoSettings {
  std::string scene = "parking_lot";  // a built-in scene name or a scene file
  std::string out_dir = "out";
  std::string segment_object;  // object name to cut out; "" = the scene's choice ("demo"."cut")
  std::string json_path;       // --json: summary.json's content here too ("-" = stdout)
  bool quiet = false;
};

std::string SceneName(const std::string& scene) { return fs::path(scene).stem().string(); }

DemoVerifyEntry VerifyEntry(const std::string& object, const std::string& pose_name,
                            const VerifyResult& result) {
  return {.object = object,
          .pose = pose_name,
          .consistency = result.consistency,
          .comparable_pairs = result.comparable_pairs,
          .confidence = result.confidence,
          .icp_cost = result.icp_cost_m,
          .inlier_fraction = result.inlier_fraction};
}

// A scene object as a verification model: its mesh, ModelOptions and world_from_model. A scene's uniform
// "scale" becomes ModelOptions::model_scale (the measures stay in metres and the neighbour grids apply); any
// other linear part (per-axis scale, a mirror, a sheared "matrix") is baked into the mesh, leaving the pose a
// translation.
struct ObjectModel {
  TriangleMesh mesh;
  ModelOptions options;
  Eigen::Matrix4d world_from_model = Eigen::Matrix4d::Identity();
};

ObjectModel ObjectAsModel(const SceneObject& object) {
  ObjectModel model;
  const Eigen::Matrix4d& pose = object.world_from_object;
  if (PoseProblem(pose, /*allow_uniform_scale=*/true).empty()) {
    const double scale = std::cbrt(pose.topLeftCorner<3, 3>().determinant());
    model.mesh = object.mesh;
    model.options.model_scale = scale;
    model.world_from_model = pose;
    model.world_from_model.topLeftCorner<3, 3>() /= scale;
  } else {
    Eigen::Matrix4d linear = Eigen::Matrix4d::Identity();
    linear.topLeftCorner<3, 3>() = pose.topLeftCorner<3, 3>();
    model.mesh = TransformMesh(object.mesh, linear);
    model.world_from_model.topRightCorner<3, 1>() = pose.topRightCorner<3, 1>();
  }
  return model;
}

// Objects worth verifying stand up from the ground: flat patches (ground,
// verges, paths) have no pose to check.
bool IsStandingObject(const SceneObject& object) {
  if (object.label == 0 || object.mesh.empty()) return false;
  const Eigen::AlignedBox3f bounds = Bounds(TransformMesh(object.mesh, object.world_from_object));
  return bounds.sizes().z() > 0.2f;
}

// Step 2: every standing object at its true pose and at two wrong poses: 1 m towards
// the scanner (in front of the seen surface: inconsistent) and 1 m away (in its shadow: consistent, unseen).
std::vector<DemoVerifyEntry> RunVerifyStep(const SceneDescription& scene, const Scan& scan,
                                           const fs::path& out_dir, Progress* progress) {
  const std::vector<PreparedScan> scans = {PrepareScan(scan)};
  const Eigen::Vector3d scanner_in_world = scan.world_from_scanner.topRightCorner<3, 1>();
  VerifyOptions options;
  std::vector<DemoVerifyEntry> entries;
  for (const SceneObject& object : scene.objects) {
    if (!IsStandingObject(object)) continue;
    const ObjectModel object_model = ObjectAsModel(object);
    const VerifierModel model = PrepareModel(object_model.mesh, object_model.options, options);
    const Eigen::Vector3d center =
        object.world_from_object.topLeftCorner<3, 3>() * Bounds(object.mesh).center().cast<double>() +
        object.world_from_object.topRightCorner<3, 1>();
    Eigen::Vector3d towards_scanner = scanner_in_world - center;
    towards_scanner.z() = 0;
    towards_scanner.normalize();
    const std::vector<std::pair<std::string, Eigen::Matrix4d>> poses = {
        {"true", object_model.world_from_model},
        {"1 m towards the scanner",
         [&] {
           Eigen::Matrix4d pose = object_model.world_from_model;
           pose.topRightCorner<3, 1>() += towards_scanner;
           return pose;
         }()},
        {"1 m away from the scanner", [&] {
           Eigen::Matrix4d pose = object_model.world_from_model;
           pose.topRightCorner<3, 1>() -= towards_scanner;
           return pose;
         }()}};
    for (const auto& [pose_name, pose] : poses) {
      VerifyOptions detail_options = options;
      detail_options.keep_details = pose_name == "true";
      const VerifyResult result = VerifyPose(model, scans, pose, detail_options);
      entries.push_back(VerifyEntry(object.name, pose_name, result));
    }
    Advance(progress);
  }
  json file = json::array();  // keys sorted, as summary.json's
  for (const DemoVerifyEntry& entry : entries) file.push_back(json(ToJson(entry)));
  WriteTextAtomically(out_dir / "verify.json", file.dump(2) + "\n");
  return entries;
}

// Step 2b (scenes with cars): sweep one car's model over the lot — heat maps and detections.
struct DemoSweep {
  std::string object;  // the scene object whose mesh is the model
  SweepOptions options;
};

// The scene's sweep ("demo"."sweep"), if it has one.
std::optional<DemoSweep> SceneSweep(const SceneDescription& scene) {
  if (scene.demo.sweep_object.empty()) return std::nullopt;
  DemoSweep sweep;
  sweep.object = scene.demo.sweep_object;
  if (!scene.demo.sweep_options_json.empty()) {
    sweep.options = FromJson<SweepOptions>(json::parse(scene.demo.sweep_options_json));
  }
  return sweep;
}

DemoSweepSummary RunSweepStep(const SceneDescription& scene, const Scan& scan, const DemoSweep& demo_sweep,
                              const fs::path& out_dir, Progress* progress) {
  const SceneObject* model_object = nullptr;
  for (const SceneObject& object : scene.objects) {
    if (object.name == demo_sweep.object) model_object = &object;
  }
  if (model_object == nullptr) {
    throw InputError(fmt::format("demo: the scene has no object named '{}' to sweep", demo_sweep.object));
  }
  const std::vector<PreparedScan> scans = {PrepareScan(scan)};
  const VerifyOptions verify_options;
  // The sweep's poses are x, y, yaw of the model's origin: the object's scale goes into the model.
  const ObjectModel object_model = ObjectAsModel(*model_object);
  const VerifierModel model = PrepareModel(object_model.mesh, object_model.options, verify_options);
  const SweepResult sweep = Sweep(model, scans, demo_sweep.options, verify_options, progress);
  WriteImage((out_dir / "sweep_consistency.png").string(),
             RenderHeatMap(sweep.consistency_map, sweep, "consistency (best over yaws)",
                           demo_sweep.options.min_consistency));
  WriteImage((out_dir / "sweep_confidence.png").string(),
             RenderHeatMap(sweep.confidence_map, sweep, "confidence (best over yaws)",
                           demo_sweep.options.min_confidence));
  WriteTextAtomically(out_dir / "sweep.csv", SweepCsv(sweep));
  const Eigen::Vector3d truth = model_object->world_from_object.topRightCorner<3, 1>();
  DemoSweepSummary summary{.model = demo_sweep.object,
                           .true_position = {truth.x(), truth.y()},
                           .poses = sweep.poses.size() + static_cast<size_t>(sweep.refine_evaluations)};
  for (const Detection& detection : sweep.detections) {
    summary.detections.push_back({.x = detection.x_m,
                                  .y = detection.y_m,
                                  .yaw_deg = detection.yaw_deg,
                                  .consistency = detection.consistency,
                                  .confidence = detection.confidence});
  }
  return summary;
}

// Step 3: cut one object out from automatic strokes and score it against the scanner's labels.
DemoSegmentSummary RunSegmentStep(const SceneDescription& scene, const Scan& scan,
                                  const std::string& object_name, const fs::path& out_dir, cv::Mat* mask) {
  const SceneObject* target = nullptr;
  for (const SceneObject& object : scene.objects) {
    if (object.name == object_name) target = &object;
  }
  if (target == nullptr) {
    throw InputError(fmt::format("demo: the scene has no object named '{}' to segment", object_name));
  }
  const cv::Mat truth = scan.label == target->label;
  const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, /*seed=*/1);
  const SegmentResult result = SegmentObject(scan, strokes, SegmentOptions{});
  const MaskScores scores = ScoreMask(result.mask, truth, scan.valid);
  WriteImage((out_dir / "segment_mask.png").string(), result.mask);
  WriteImage((out_dir / "segment_strokes.png").string(), StrokesToImage(strokes));
  WriteImage((out_dir / "segment_overlay.png").string(), SegmentOverlay(scan, result.mask, strokes));
  *mask = result.mask;
  return {.object = object_name,
          .label = target->label,
          .iou = scores.iou,
          .precision = scores.precision,
          .recall = scores.recall,
          .object_cells = result.object_cells,
          .seconds = result.timings.total_s};
}

// Step 4: remove the cut-out object — fill its cells grown by 2 — and score the fill against the scene
// scanned again without the object (the scanner's noise is a function of the cell and the seed, so
// every other cell is the same).
DemoRemoveSummary RunRemoveStep(const SceneDescription& scene, const Scan& scan,
                                const std::string& object_name, const cv::Mat& object_mask,
                                const fs::path& out_dir, Progress* progress) {
  SceneDescription without = scene;
  std::erase_if(without.objects, [&](const SceneObject& object) { return object.name == object_name; });
  const cv::Mat hole = GrowHole(object_mask, 2);
  progress->Restart("demo: filling", cv::countNonZero(hole));
  const FillResult fill = FillScan(scan, hole, FillOptions{}, progress);
  const Scan truth = SyntheticScanner(without).Acquire(scene.scanner);
  const FillMetrics m = MeasureFill(fill.scan, truth, hole);
  WriteScanFile((out_dir / "removed.e57").string(), {fill.scan});
  RenderOptions range;
  range.channel = RenderChannel::kRange;
  range.legend = true;
  WriteImage((out_dir / "remove_range.png").string(), RenderPicture(fill.scan, range, {}).image);
  PointViewOptions view = SideView(truth, hole, 35.0);
  view.width_px = 540;
  view.height_px = 360;
  WriteImage((out_dir / "remove_view_scan.png").string(), RenderPointView(scan, view));
  WriteImage((out_dir / "remove_view_truth.png").string(), RenderPointView(truth, view));
  view.synthesized_tint = 0.4;
  WriteImage((out_dir / "remove_view_filled.png").string(), RenderPointView(fill.scan, view));
  return {.object = object_name,
          .hole_cells = fill.hole_cells,
          .synthesized_points = fill.synthesized_cells,
          .no_return_cells = fill.no_return_cells,
          .range_rmse_mm = m.range_rmse_mm,
          .range_mae_mm = m.range_mae_mm,
          .within_20mm = m.within_share,
          .floating_points = m.floating_share,
          .return_accuracy = m.return_accuracy,
          .color_psnr_db = m.color_psnr_db,
          .seconds = fill.timings.total_s};
}

// The scan with its colour showing where each filled cell came from: another station's measurement cyan,
// synthesized magenta, the rest as scanned.
Scan ColoredBySource(const Scan& scan) {
  Scan shown = Clone(scan);
  if (shown.color.empty()) shown.color = cv::Mat(scan.rows, scan.cols, CV_8UC3, cv::Scalar(128, 128, 128));
  if (!scan.from_station.empty()) shown.color.setTo(cv::Scalar(0, 200, 230), scan.from_station != 0);
  if (!scan.synthesized.empty()) shown.color.setTo(cv::Scalar(230, 0, 200), scan.synthesized != 0);
  return shown;
}

// Step 4b: the object removed from station 0 of the scene's site, its hole filled from station 2 first (none
// when the site lacks the object or a station 2).
std::optional<DemoStationsSummary> RunStationsStep(const std::string& site_name,
                                                   const std::string& object_name, const cv::Mat& object_mask,
                                                   const fs::path& out_dir, Progress* progress) {
  const SceneDescription site = LoadSceneOrBuiltin(site_name);
  const SceneObject* target = nullptr;
  for (const SceneObject& object : site.objects)
    if (object.name == object_name) target = &object;
  if (target == nullptr || site.NumStations() < 3) return std::nullopt;
  progress->Restart("demo: filling from station 2", 4);
  const Scan station0 = SynthesizeScan(SceneAtStation(site, 0));
  const Scan station2 = SynthesizeScan(SceneAtStation(site, 2));
  SceneDescription without = SceneAtStation(site, 0);
  std::erase_if(without.objects, [&](const SceneObject& object) { return object.name == object_name; });
  const Scan truth = SynthesizeScan(without);
  progress->Advance(3);
  // The segmentation step's cut when station 0 has the scene's grid, else the object's true cells.
  const cv::Mat object = object_mask.size() == station0.valid.size()
                             ? object_mask
                             : (station0.label == target->label) & (station0.valid != 0);
  const cv::Mat hole = GrowHole(object, 2);
  const FromStationsResult filled = FillFromStations(station0, hole, {station2});
  progress->Advance();
  // The range error of the cells taken from station 2 against the truth, and the whole fill's metrics.
  double sum = 0;
  int64_t compared = 0;
  for (int r = 0; r < truth.rows; ++r) {
    for (int c = 0; c < truth.cols; ++c) {
      if (filled.from_station.at<uint8_t>(r, c) == 0 || truth.valid.at<uint8_t>(r, c) == 0) continue;
      const double error = filled.scan.range.at<float>(r, c) - truth.true_range.at<float>(r, c);
      sum += error * error;
      ++compared;
    }
  }
  const FillMetrics m = MeasureFill(filled.scan, truth, hole);
  WriteScanFile((out_dir / "stations.e57").string(), {filled.scan});
  PointViewOptions view = SideView(truth, hole, 35.0);
  view.width_px = 540;
  view.height_px = 360;
  WriteImage((out_dir / "stations_view_scan.png").string(), RenderPointView(station0, view));
  WriteImage((out_dir / "stations_view_filled.png").string(),
             RenderPointView(ColoredBySource(filled.scan), view));
  RenderOptions rgb;
  rgb.channel = RenderChannel::kRgb;
  WriteImage((out_dir / "stations_rays.png").string(),
             RenderPicture(ColoredBySource(filled.scan), rgb, {}).image);
  return DemoStationsSummary{.object = object_name,
                             .site = site_name,
                             .hole_cells = filled.hole_cells,
                             .from_station_cells = filled.from_station_cells,
                             .synthesized_cells = filled.synthesized_cells,
                             .no_return_cells = filled.no_return_cells,
                             .from_station_rmse_mm = compared > 0 ? 1000 * std::sqrt(sum / compared) : 0.0,
                             .range_rmse_mm = m.range_rmse_mm,
                             .floating_points = m.floating_share,
                             .seconds = filled.stations_seconds + filled.fill_seconds};
}

// Step 1's pictures: every channel with its legend (square angular pixels), the range as float metres, and
// the points from above (a second viewpoint: what the ray picture cannot show, distances on the ground).
void WriteScanPictures(const SceneDescription& scene, const Scan& scan, const fs::path& out_dir) {
  const std::vector<std::pair<std::string, RenderChannel>> views = {{"rgb", RenderChannel::kRgb},
                                                                    {"range", RenderChannel::kRange},
                                                                    {"intensity", RenderChannel::kIntensity},
                                                                    {"labels_view", RenderChannel::kLabels},
                                                                    {"normals", RenderChannel::kNormals}};
  for (const auto& [name, channel] : views) {
    RenderOptions options;
    options.channel = channel;
    options.legend = channel != RenderChannel::kRgb;
    options.label_names = ObjectNamesByLabel(scene);
    WriteImage((out_dir / (name + ".png")).string(), RenderPicture(scan, options, {}).image);
  }
  PictureLayoutOptions native;
  native.aspect = PixelAspect::kNative;
  WriteImage((out_dir / "range.exr").string(), RenderValues(scan, RenderChannel::kRange, native).values);
  // A bird's-eye view of the points (perspective, point splats): from above and behind the scanner, looking at
  // the standing objects. An orthographic top view of a terrestrial scan is mostly empty pixels between the
  // ground's scan lines.
  Eigen::AlignedBox3d around;
  for (const SceneObject& object : scene.objects) {
    if (IsStandingObject(object)) around.extend(Bounds(MeshInWorld(object)).cast<double>());
  }
  const Eigen::Vector3d scanner = scan.world_from_scanner.topRightCorner<3, 1>();
  const Eigen::Vector3d target = around.isEmpty() ? Eigen::Vector3d(scanner + Eigen::Vector3d(0, 10, 0))
                                                  : Eigen::Vector3d(around.center());
  Eigen::Vector3d back = scanner - target;
  back.z() = 0;
  back = back.norm() > 1e-6 ? back.normalized() : Eigen::Vector3d(0, -1, 0);
  const double distance = std::max(8.0, (target - scanner).norm());
  PointViewOptions bird;
  bird.target_in_world = target;
  bird.eye_in_world = target + back * (1.3 * distance) + Eigen::Vector3d(0, 0, 0.9 * distance);
  bird.width_px = 900;
  bird.height_px = 560;
  WriteImage((out_dir / "top_view.png").string(), RenderPointView(scan, bird));
}

int RunDemoSteps(const DemoSettings& settings) {
  const fs::path out_dir(settings.out_dir);
  fs::create_directories(out_dir);
  const std::string scene_name = SceneName(settings.scene);
  DemoSummary summary{.scene = scene_name};
  DemoSeconds& seconds = summary.seconds;
  auto progress = Progress::ForTerminal("demo: loading", 1, settings.quiet);

  Timer timer;
  const SceneDescription scene = LoadSceneOrBuiltin(settings.scene);
  PrintWarnings(scene.warnings);
  const SyntheticScanner scanner(scene);
  seconds.load = timer.Seconds();

  timer.Restart();
  progress->Restart("demo: scanning", scene.scanner.rows);
  const Scan scan = scanner.Acquire(scene.scanner, progress.get());
  seconds.scan = timer.Seconds();
  summary.scan = {
      .rows = scan.rows, .cols = scan.cols, .valid = scan.CountValid(), .triangles = scanner.num_triangles()};

  timer.Restart();
  progress->Restart("demo: writing the scan", 4);
  WriteScanFile((out_dir / "scan.ptx").string(), {scan});
  progress->Advance();
  WriteScanFile((out_dir / "scan.e57").string(), {scan});
  progress->Advance();
  WriteImage((out_dir / "labels.png").string(), LabelImage16(scan));
  WriteScanPictures(scene, scan, out_dir);
  progress->Advance(2);
  seconds.write = timer.Seconds();

  timer.Restart();
  int objects_to_verify = 0;
  for (const SceneObject& object : scene.objects) objects_to_verify += IsStandingObject(object) ? 1 : 0;
  progress->Restart("demo: verifying", objects_to_verify);
  summary.verify = RunVerifyStep(scene, scan, out_dir, progress.get());
  seconds.verify = timer.Seconds();

  if (const std::optional<DemoSweep> demo_sweep = SceneSweep(scene)) {
    timer.Restart();
    progress->Restart("demo: sweeping", 1);
    summary.sweep = RunSweepStep(scene, scan, *demo_sweep, out_dir, nullptr);
    progress->Advance();
    seconds.sweep = timer.Seconds();
  }

  const std::string segment_object =
      settings.segment_object.empty() ? scene.demo.cut_object : settings.segment_object;
  if (!segment_object.empty()) {
    timer.Restart();
    progress->Restart("demo: segmenting", 1);
    cv::Mat object_mask;
    summary.segment = RunSegmentStep(scene, scan, segment_object, out_dir, &object_mask);
    progress->Advance();
    seconds.segment = timer.Seconds();
    timer.Restart();
    summary.remove = RunRemoveStep(scene, scan, segment_object, object_mask, out_dir, progress.get());
    seconds.remove = timer.Seconds();
    if (const std::string& site = scene.demo.site; !site.empty()) {
      timer.Restart();
      summary.stations = RunStationsStep(site, segment_object, object_mask, out_dir, progress.get());
      if (summary.stations) {
        seconds.stations = timer.Seconds();
      }
    }
  }
  progress->Finish();

  const json summary_json = DemoSummaryJson(summary);
  WriteTextAtomically(out_dir / "summary.json", summary_json.dump(2) + "\n");
  WriteTextAtomically(out_dir / "index.html", DemoPage(scene_name, summary));
  WriteJsonOutput(settings.json_path, summary_json);
  Summarize(fmt::format("scene '{}', {} x {} rays, {} returns; results in {}/ (open index.html)", scene_name,
                        scan.rows, scan.cols, scan.CountValid(), out_dir.string()));
  return 0;
}

}  // namespace

int RunDemo(int argc, char** argv) {
  CLI::App app(
      "Run the main job on a built-in scene: scan it, verify object poses, cut an object out and remove it. "
      "Every result goes to --out, with index.html to look at them.",
      "demo");
  DemoSettings settings;
  std::string scene_help = "a built-in scene (";
  for (const BuiltinScene& builtin : BuiltinScenes()) scene_help += fmt::format("{} ", builtin.name);
  scene_help += ") or a scene JSON file";
  app.add_option("--scene", settings.scene, scene_help)->capture_default_str();
  app.add_option("--out", settings.out_dir, "output folder (created if missing)")->capture_default_str();
  app.add_option("--segment-object", settings.segment_object,
                 "name of the scene object to cut out (default: the built-in scene's choice)");
  AddJsonOption(app, &settings.json_path);
  AddQuietFlag(app, &settings.quiet);
  return RunCommand(app, argc, argv, [&] {
    const std::string summary_path = (fs::path(settings.out_dir) / "summary.json").string();
    CheckOutputFile("--json", settings.json_path, {}, {summary_path});
    return RunDemoSteps(settings);
  });
}

}  // namespace lidarshop::cli
