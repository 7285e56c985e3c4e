// lidarshop verify | sweep: consistency and confidence of object poses (verify/verify.h, verify/sweep.h).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/verify/pose_text.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::cli {
namespace {

std::vector<PreparedScan> LoadScans(const std::vector<std::string>& paths) {
  std::vector<PreparedScan> scans;
  for (const std::string& path : paths) {
    const ScanFile file = ReadScanFileAndWarn(path);
    if (file.scans.empty()) throw InputError(fmt::format("{}: no scan in the file", path));
    for (const Scan& scan : file.scans) scans.push_back(PrepareScan(scan));
  }
  return scans;
}

// A mesh file, or "builtin:sedan" / "builtin:hatchback" / "builtin:van": the scanner module's procedural cars
// (the ones of data/scenes/parking_lot.json), in their own frame (standing on z = 0, length along y).
TriangleMesh LoadModel(const std::string& path) {
  const std::string prefix = "builtin:";
  if (path.rfind(prefix, 0) == 0) {
    CarMeshOptions options;
    options.style = ParseCarStyle(path.substr(prefix.size()), "--model");
    return MakeCarMesh(options);
  }
  return ReadMeshAndWarn(path);
}

// The flags verify and sweep share: scans, the model and the options of both sides (VerifyOptions first:
// `--options FILE` sets it).
struct CommonFlags {
  std::vector<std::string> scans;
  std::string model;
  VerifyOptions verify;
  ModelOptions model_options;
  bool use_vertices = false;
  bool distinctiveness = false;
  bool quiet = false;

  void Add(CLI::App& app, OptionBinder& binder) {
    app.add_option(
           "--scan", scans,
           "scan file (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts); repeat for several registered scans")
        ->required();
    app.add_option("--model", model,
                   "model mesh (.obj, .ply) in its own frame, metres; or builtin:sedan|hatchback|van "
                   "(procedural cars)")
        ->required();
    // allowance_m: ~2-3x the range noise + the model's error (0.02 for a 30 cm object); sigma_m: ~ the
    // scan's point spacing on the object. keep_details follows --scene-points / --model-points.
    binder.Bind(&verify, {.skip = {"keep_details"},
                          .flags = {{"allowance_m", "--allowance"},
                                    {"sigma_m", "--sigma"},
                                    {"icp_trim_m", "--icp-trim"},
                                    {"footprint_margin_cells", "--footprint-margin"}}});
    binder.Bind(&model_options, {.flags = {{"num_surface_samples", "--samples"}}, .group = "Model points"});
    app.add_flag("--vertices", use_vertices, "= --point-source vertices")->group("Model points");
    app.add_flag("--distinctiveness", distinctiveness, "= --information shape-distinctiveness")
        ->group("Model points");
    AddQuietFlag(app, &quiet);
  }

  VerifierModel PrepareTheModel(const OptionBinder& binder) {
    if (use_vertices) model_options.point_source = ModelPointSource::kVertices;
    if (distinctiveness) model_options.information = InformationWeighting::kShapeDistinctiveness;
    binder.Validate(model_options);
    binder.Validate(verify);
    return PrepareModel(LoadModel(model), model_options, verify);
  }
};

// "a:b" → {a, b}.
std::pair<double, double> ParseRange(const std::string& text, const std::string& flag) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos)
    throw OptionsError(fmt::format("{}: expected MIN:MAX, got '{}'", flag, text));
  const std::vector<double> lo = ParseNumbers(text.substr(0, colon), flag);
  const std::vector<double> hi = ParseNumbers(text.substr(colon + 1), flag);
  if (lo.size() != 1 || hi.size() != 1)
    throw OptionsError(fmt::format("{}: expected MIN:MAX, got '{}'", flag, text));
  return {lo[0], hi[0]};
}

// "0,90,180" (a list) or "0:360:15" (start:stop:step, stop excluded).
std::vector<double> ParseYaws(const std::string& text) {
  if (text.find(':') != std::string::npos) {
    std::string spaced = text;
    for (char& c : spaced) {
      if (c == ':') c = ' ';
    }
    const std::vector<double> parts = ParseNumbers(spaced, "--yaws");
    if (parts.size() != 3 || !(parts[2] > 0) || parts[1] <= parts[0]) {
      throw OptionsError(fmt::format("--yaws: expected START:STOP:STEP with STEP > 0, got '{}'", text));
    }
    // Count before expanding: 0:1e9:1e-9 must not try to build 10^18 yaws (nor loop forever when the step
    // vanishes beside the start).
    constexpr double kMaxYaws = 100000;
    const double count = std::ceil((parts[1] - parts[0]) / parts[2]);
    if (!(count <= kMaxYaws) || !std::isfinite(parts[0]) || !std::isfinite(parts[1]) ||
        parts[0] + parts[2] == parts[0]) {
      throw OptionsError(
          fmt::format("--yaws: '{}' gives {} yaws, more than the {} accepted", text, count, kMaxYaws));
    }
    std::vector<double> yaws;
    for (int64_t i = 0; i < static_cast<int64_t>(count); ++i) {
      const double yaw = parts[0] + static_cast<double>(i) * parts[2];
      if (yaw < parts[1] - 1e-9) yaws.push_back(yaw);
    }
    return yaws;
  }
  return ParseNumbers(text, "--yaws");
}

}  // namespace

int RunVerify(int argc, char** argv) {
  CLI::App app(
      "Consistency and confidence of a hypothesized object pose against one or many registered scans (thesis "
      "eqs. "
      "4.1-4.6), with the trimmed ICP cost as a baseline. Prints a one-line summary; --json writes every "
      "number.",
      "verify");
  CommonFlags common;
  OptionBinder binder(app);
  std::string pose_text, json_path, scene_ply, model_ply;
  common.Add(app, binder);
  app.add_option(
         "--pose", pose_text,
         "world_from_model: a file (4 rows of 4 numbers, or JSON), 16 comma-separated numbers (row major), "
         "or x,y,z,yaw_deg[,pitch_deg,roll_deg] (world frame, metres and degrees; "
         "R = Rz(yaw)·Ry(pitch)·Rx(roll))")
      ->required();
  AddJsonOption(app, &json_path);
  app.add_option("--scene-points", scene_ply,
                 "write the scene points (world frame) as PLY: green consistent, red inconsistent, grey not "
                 "comparable (label 1 / 2 / 0)");
  app.add_option(
      "--model-points", model_ply,
      "write the posed model points as PLY coloured by observed information: red unseen -> green seen");
  return RunCommand(
      app, argc, argv,
      [&] {
        std::vector<std::string> used = common.scans;
        used.push_back(common.model);
        used.push_back(pose_text);
        for (const std::string& path : {json_path, scene_ply, model_ply}) {
          if (path.empty() || path == "-") continue;
          CheckOutputPath(path, used);
          used.push_back(path);
        }
        const Eigen::Matrix4d world_from_model = ParsePose(pose_text);
        auto progress = Progress::ForTerminal("verify: preparing", 2, common.quiet);
        VerifierModel model = common.PrepareTheModel(binder);
        progress->Advance();
        const std::vector<PreparedScan> scans = LoadScans(common.scans);
        progress->Advance();
        progress->Finish();
        VerifyOptions options = common.verify;
        options.keep_details = !scene_ply.empty() || !model_ply.empty();
        const VerifyResult result = VerifyPose(model, scans, world_from_model, options);
        Summarize(result.BriefReport());
        const VerifyReport report = MakeVerifyReport(result, model, common.model_options, world_from_model);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(report)));
        if (!scene_ply.empty()) WritePointCloud(scene_ply, SceneStatusCloud(scans, result));
        if (!model_ply.empty())
          WritePointCloud(model_ply, ObservedModelCloud(model, world_from_model, result));
        return 0;
      },
      &binder);
}

int RunSweep(int argc, char** argv) {
  CLI::App app(
      "Consistency and confidence for a grid of candidate poses on a ground plane (x, y, yaw), written as "
      "two heat "
      "maps with colour scales, a CSV of every pose and the detections that pass both thresholds after local "
      "refinement and non-maximum suppression.\n"
      "Outputs in --out: consistency.png, confidence.png (best value over yaws per position, north up, rings "
      "at "
      "detections, axes in metres, the scanner and the scene points), sweep.csv (the verified poses), "
      "detections.json.\n"
      "--search coarse-to-fine (default) verifies only the blocks of poses whose confidence bound can still "
      "pass and gives the same detections as --search full.",
      "sweep");
  CommonFlags common;
  SweepOptions sweep_options;
  sweep_options.yaws_deg = ParseYaws("0:360:15");  // the command's default: every 15 degrees
  std::string x_range, y_range, yaws, out_dir, json_path;
  OptionBinder binder(app);
  // The sweep's options first: `--options FILE` sets them. The ranges and yaws keep their own syntax.
  binder.Bind(&sweep_options, {.skip = {"x_min_m", "x_max_m", "y_min_m", "y_max_m", "yaws_deg"},
                               .flags = {{"step_m", "--step"},
                                         {"z_m", "--z"},
                                         {"min_comparable_pairs", "--min-pairs"},
                                         {"nms_radius_m", "--nms-radius"}}});
  app.add_option("--x-range", x_range, "MIN:MAX world x of the model origin, metres")->default_str("-10:10");
  app.add_option("--y-range", y_range, "MIN:MAX world y of the model origin, metres")->default_str("0:20");
  app.add_option("--yaws", yaws, "yaws in degrees: a list '0,90,180' or START:STOP:STEP (STOP excluded)")
      ->default_str("0:360:15");
  for (const char* key : {"x_min_m", "x_max_m"}) binder.NameFlag(key, "--x-range");
  for (const char* key : {"y_min_m", "y_max_m"}) binder.NameFlag(key, "--y-range");
  binder.NameFlag("yaws_deg", "--yaws");
  common.Add(app, binder);
  app.add_option("--out", out_dir, "output folder (created)")->required();
  AddJsonOption(app, &json_path);
  return RunCommand(
      app, argc, argv,
      [&] {
        if (!x_range.empty())
          std::tie(sweep_options.x_min_m, sweep_options.x_max_m) = ParseRange(x_range, "--x-range");
        if (!y_range.empty())
          std::tie(sweep_options.y_min_m, sweep_options.y_max_m) = ParseRange(y_range, "--y-range");
        if (!yaws.empty()) sweep_options.yaws_deg = ParseYaws(yaws);
        binder.Validate(sweep_options);
        CheckOutputFile("--json", json_path, {}, common.scans);
        VerifierModel model = common.PrepareTheModel(binder);
        const std::vector<PreparedScan> scans = LoadScans(common.scans);
        std::filesystem::create_directories(out_dir);
        const std::filesystem::path out(out_dir);
        const size_t poses =
            (static_cast<size_t>(
                 std::floor((sweep_options.x_max_m - sweep_options.x_min_m) / sweep_options.step_m + 1e-9)) +
             1) *
            (static_cast<size_t>(
                 std::floor((sweep_options.y_max_m - sweep_options.y_min_m) / sweep_options.step_m + 1e-9)) +
             1) *
            sweep_options.yaws_deg.size();
        auto progress = Progress::ForTerminal("sweep", static_cast<int64_t>(poses), common.quiet);
        const SweepResult sweep = Sweep(model, scans, sweep_options, common.verify, progress.get());
        progress->Finish();
        WriteImage((out / "consistency.png").string(),
                   RenderHeatMap(sweep.consistency_map, sweep, "consistency (best over yaws)",
                                 sweep_options.min_consistency));
        WriteImage((out / "confidence.png").string(),
                   RenderHeatMap(sweep.confidence_map, sweep, "confidence (best over yaws)",
                                 sweep_options.min_confidence));
        WriteTextAtomically((out / "sweep.csv").string(), SweepCsv(sweep));
        const SweepReport report{.summary = SummarizeSweep(sweep, sweep_options),
                                 .verify_options = common.verify,
                                 .model_options = common.model_options};
        WriteTextAtomically((out / "detections.json").string(), ToJson(report.summary).dump(2) + "\n");
        WriteJsonOutput(json_path, CommandJson(ToJson(sweep_options), ToJson(report)));
        if (!common.quiet) {
          for (const Detection& d : sweep.detections) {
            fmt::print(stderr,
                       "  detection at x {:.2f} y {:.2f} yaw {:.1f}: consistency {:.3f}, confidence {:.3f}\n",
                       d.x_m, d.y_m, d.yaw_deg, d.consistency, d.confidence);
          }
        }
        Summarize(fmt::format("{} poses ({} verified), {} refined, {} detection(s) -> {}", sweep.poses.size(),
                              sweep.evaluated_poses, sweep.refined.size(), sweep.detections.size(),
                              (out / "detections.json").string()));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
