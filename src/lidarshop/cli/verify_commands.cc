// lidarshop verify | sweep: consistency and confidence of object poses (verify/verify.h, verify/sweep.h).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
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
    const ScanFile file = ReadScanFile(path);
    if (file.scans.empty()) throw InputError(fmt::format("{}: no scan in the file", path));
    for (const Scan& scan : file.scans) scans.push_back(PrepareScan(scan));
  }
  return scans;
}

nlohmann::json NumberOrNull(double value) {
  return std::isnan(value) ? nlohmann::json() : nlohmann::json(value);
}

nlohmann::json ResultJson(const VerifyResult& result, const std::vector<std::string>& scan_names) {
  nlohmann::json json;
  json["consistency"] = NumberOrNull(result.consistency);
  json["has_comparable_pairs"] = result.has_comparable_pairs;
  json["comparable_pairs"] = result.comparable_pairs;
  json["consistent_pairs"] = result.consistent_pairs;
  json["confidence"] = result.confidence;
  json["icp_cost"] = NumberOrNull(result.icp_cost_m);
  json["icp_inliers"] = result.icp_inliers;
  json["icp_candidates"] = result.icp_candidates;
  json["inlier_fraction"] = result.inlier_fraction;
  json["per_scan"] = nlohmann::json::array();
  for (size_t s = 0; s < result.per_scan.size(); ++s) {
    const ScanVerifyStats& stats = result.per_scan[s];
    json["per_scan"].push_back({{"scan", s < scan_names.size() ? scan_names[s] : std::to_string(s)},
                                {"consistency", NumberOrNull(stats.consistency)},
                                {"comparable_pairs", stats.comparable_pairs},
                                {"consistent_pairs", stats.consistent_pairs},
                                {"confidence", stats.confidence},
                                {"footprint_cells", stats.footprint_cells},
                                {"rays_cast", stats.rays_cast}});
  }
  return json;
}

nlohmann::json MatrixJson(const Eigen::Matrix4d& matrix) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  return rows;
}

void WriteText(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& stream) { stream << text; });
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
  return ReadMesh(path);
}

struct CommonFlags {
  std::vector<std::string> scans;
  std::string model;
  VerifyOptions verify;
  ModelOptions model_options;
  bool use_vertices = false;
  bool distinctiveness = false;
  bool quiet = false;

  void Add(CLI::App& app) {
    app.add_option(
           "--scan", scans,
           "scan file (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts); repeat for several registered scans")
        ->required();
    app.add_option("--model", model,
                   "model mesh (.obj, .ply) in its own frame, metres; or builtin:sedan|hatchback|van "
                   "(procedural cars)")
        ->required();
    app.add_option(
           "--allowance", verify.allowance_m,
           "mismatch allowance a, metres (consistency: (d_m + a) - d_s >= 0); ~2-3x range noise + model "
           "error; 0.02 for a 30 cm object")
        ->capture_default_str();
    app.add_option(
           "--sigma", verify.sigma_m,
           "observation kernel sigma, metres (confidence: neighbours within 3 sigma); ~ the scan's point "
           "spacing on the object")
        ->capture_default_str();
    app.add_option("--icp-trim", verify.icp_trim_m, "trimmed ICP: pairs beyond this are excluded, metres")
        ->capture_default_str();
    app.add_option("--samples", model_options.num_surface_samples,
                   "model points sampled uniformly on the surface (confidence)")
        ->capture_default_str();
    AddSeedOption(app, &model_options.seed, "seed of the surface sampling");
    app.add_flag("--vertices", use_vertices,
                 "use the mesh vertices as model points instead of surface samples");
    app.add_flag("--distinctiveness", distinctiveness,
                 "weight model points by shape distinctiveness (surface variation) instead of uniformly");
    AddQuietFlag(app, &quiet);
  }

  VerifierModel PrepareTheModel() {
    if (use_vertices) model_options.point_source = ModelPointSource::kVertices;
    if (distinctiveness) model_options.information = InformationWeighting::kShapeDistinctiveness;
    model_options.Check();
    verify.Check();
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
  std::string pose_text, json_path, scene_ply, model_ply;
  common.Add(app);
  app.add_option(
         "--pose", pose_text,
         "world_from_model: a file of 4 rows of 4 numbers, 16 comma-separated numbers (row major), or "
         "x,y,z,yaw_deg[,pitch_deg,roll_deg] (world frame, metres and degrees)")
      ->required();
  app.add_option("--json", json_path,
                 "write the result as JSON (consistency, confidence, comparable_pairs, "
                 "icp_cost, inlier_fraction, per_scan, ...)");
  app.add_option("--scene-points", scene_ply,
                 "write the scene points (world frame) as PLY: green consistent, red inconsistent, grey not "
                 "comparable (label 1 / 2 / 0)");
  app.add_option(
      "--model-points", model_ply,
      "write the posed model points as PLY coloured by observed information: red unseen -> green seen");
  return RunCommand(app, argc, argv, [&] {
    std::vector<std::string> used = common.scans;
    used.push_back(common.model);
    used.push_back(pose_text);
    for (const std::string& path : {json_path, scene_ply, model_ply}) {
      if (path.empty()) continue;
      CheckOutputPath(path, used);
      used.push_back(path);
    }
    const Eigen::Matrix4d world_from_model = ParsePose(pose_text);
    auto progress = Progress::ForTerminal("verify: preparing", 2, common.quiet);
    VerifierModel model = common.PrepareTheModel();
    progress->Advance();
    const std::vector<PreparedScan> scans = LoadScans(common.scans);
    progress->Advance();
    progress->Finish();
    VerifyOptions options = common.verify;
    options.keep_details = !scene_ply.empty() || !model_ply.empty();
    const VerifyResult result = VerifyPose(model, scans, world_from_model, options);
    std::vector<std::string> names;
    for (const PreparedScan& scan : scans) names.push_back(scan.scan.name);
    fmt::print("{}\n", result.BriefReport());
    if (!json_path.empty()) {
      nlohmann::json json = ResultJson(result, names);
      json["world_from_model"] = MatrixJson(world_from_model);
      json["options"] = {{"allowance_m", options.allowance_m},
                         {"sigma_m", options.sigma_m},
                         {"icp_trim_m", options.icp_trim_m},
                         {"model_points", model.num_points()}};
      WriteText(json_path, json.dump(2) + "\n");
    }
    if (!scene_ply.empty()) WritePointCloud(scene_ply, SceneStatusCloud(scans, result));
    if (!model_ply.empty()) WritePointCloud(model_ply, ObservedModelCloud(model, world_from_model, result));
    return 0;
  });
}

int RunSweep(int argc, char** argv) {
  CLI::App app(
      "Consistency and confidence for a grid of candidate poses on a ground plane (x, y, yaw), written as "
      "two heat "
      "maps with colour scales, a CSV of every pose and the detections that pass both thresholds after local "
      "refinement and non-maximum suppression.\n"
      "Outputs in --out: consistency.png, confidence.png (best value over yaws per position, north up, rings "
      "at "
      "detections), sweep.csv, detections.json.",
      "sweep");
  CommonFlags common;
  SweepOptions sweep_options;
  std::string x_range = "-10:10", y_range = "0:20", yaws = "0:360:15", out_dir;
  bool no_refine = false;
  common.Add(app);
  app.add_option("--x-range", x_range, "MIN:MAX world x of the model origin, metres")->capture_default_str();
  app.add_option("--y-range", y_range, "MIN:MAX world y of the model origin, metres")->capture_default_str();
  app.add_option("--step", sweep_options.step_m, "grid step in x and y, metres")->capture_default_str();
  app.add_option("--z", sweep_options.z_m, "world z of the model origin (the ground for a car), metres")
      ->capture_default_str();
  app.add_option("--yaws", yaws, "yaws in degrees: a list '0,90,180' or START:STOP:STEP (STOP excluded)")
      ->capture_default_str();
  app.add_option("--min-consistency", sweep_options.min_consistency, "detections need consistency > this")
      ->capture_default_str();
  app.add_option("--min-confidence", sweep_options.min_confidence, "detections need confidence > this")
      ->capture_default_str();
  app.add_option("--min-pairs", sweep_options.min_comparable_pairs,
                 "detections need at least this many pairs")
      ->capture_default_str();
  app.add_option("--nms-radius", sweep_options.nms_radius_m,
                 "non-maximum suppression radius, metres (0 = the model's smaller horizontal extent)")
      ->capture_default_str();
  app.add_flag("--no-refine", no_refine, "report grid poses only (no local refinement of promising poses)");
  app.add_option("--out", out_dir, "output folder (created)")->required();
  return RunCommand(app, argc, argv, [&] {
    std::tie(sweep_options.x_min_m, sweep_options.x_max_m) = ParseRange(x_range, "--x-range");
    std::tie(sweep_options.y_min_m, sweep_options.y_max_m) = ParseRange(y_range, "--y-range");
    sweep_options.yaws_deg = ParseYaws(yaws);
    sweep_options.refine = !no_refine;
    sweep_options.Check();
    VerifierModel model = common.PrepareTheModel();
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
    WriteText((out / "sweep.csv").string(), SweepCsv(sweep));
    nlohmann::json json;
    json["detections"] = nlohmann::json::array();
    for (const Detection& d : sweep.detections) {
      json["detections"].push_back({{"x_m", d.x_m},
                                    {"y_m", d.y_m},
                                    {"z_m", d.z_m},
                                    {"yaw_deg", d.yaw_deg},
                                    {"consistency", d.consistency},
                                    {"confidence", d.confidence},
                                    {"comparable_pairs", d.comparable_pairs},
                                    {"icp_cost", NumberOrNull(d.icp_cost_m)},
                                    {"inlier_fraction", d.inlier_fraction},
                                    {"world_from_model", MatrixJson(d.world_from_model)}});
    }
    json["thresholds"] = {{"min_consistency", sweep_options.min_consistency},
                          {"min_confidence", sweep_options.min_confidence},
                          {"min_comparable_pairs", sweep_options.min_comparable_pairs},
                          {"nms_radius_m", sweep.nms_radius_m}};
    json["grid"] = {{"x_count", sweep.xs_m.size()},
                    {"y_count", sweep.ys_m.size()},
                    {"yaws_deg", sweep.yaws_deg},
                    {"poses", sweep.poses.size()},
                    {"refined_seeds", sweep.refined.size()},
                    {"refine_evaluations", sweep.refine_evaluations}};
    WriteText((out / "detections.json").string(), json.dump(2) + "\n");
    fmt::print("{} poses, {} refined, {} detection(s):\n", sweep.poses.size(), sweep.refined.size(),
               sweep.detections.size());
    for (const Detection& d : sweep.detections) {
      fmt::print("  x {:.2f} y {:.2f} yaw {:.1f}: consistency {:.3f}, confidence {:.3f}\n", d.x_m, d.y_m,
                 d.yaw_deg, d.consistency, d.confidence);
    }
    return 0;
  });
}

}  // namespace lidarshop::cli
