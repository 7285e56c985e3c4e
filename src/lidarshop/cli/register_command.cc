// lidarshop register: point-to-plane ICP of one scan onto another, or of a whole site (docs/points.md,
// docs/stations.md).
//
//   lidarshop register FIXED MOVING -o OUT [--max-distance M] [--global] [--json FILE|-]
//   lidarshop register FIXED MOVING1 MOVING2 ... -o DIR [--json FILE|-]
//
// With one MOVING, MOVING is registered onto FIXED and written with its world_from_scanner corrected. With
// several, the site is registered (pointset/site_registration.h: pairwise ICP between overlapping stations,
// then a pose graph over every pair), FIXED stays, and DIR holds each moved station under its own file name
// (FILE#N, scan N of a site's file: FILE's stem + _N). Every input may be FILE#N.
#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/cli/scan_selector.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/pointset/site_registration.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {
namespace {

// The site: FIXED and every MOVING registered together; DIR receives the moved stations.
int RegisterSiteCommand(const std::string& fixed_path, const std::vector<std::string>& moving_paths,
                        const std::string& output_dir, const std::string& json_path, const IcpOptions& icp,
                        const SiteRegistrationOptions& site) {
  std::error_code error;
  if (!std::filesystem::is_directory(output_dir, error)) {
    throw OptionsError(
        fmt::format("-o {}: with several MOVING scans, -o names a folder (it holds each moved "
                    "station under its own file name), and {} is not one",
                    output_dir, output_dir));
  }
  std::vector<std::string> inputs = {fixed_path};
  inputs.insert(inputs.end(), moving_paths.begin(), moving_paths.end());
  std::vector<std::string> outputs;
  std::set<std::string> names;
  for (const std::string& moving : moving_paths) {
    const std::string name = StationOutputName(moving);
    if (!names.insert(name).second) {
      throw OptionsError(
          fmt::format("-o {}: two MOVING scans would both be written as {}; give files of "
                      "different names",
                      output_dir, name));
    }
    const std::string output = (std::filesystem::path(output_dir) / name).string();
    CheckScanFileFormat(output);
    std::vector<std::string> others = inputs;
    for (const std::string& input : inputs) others.push_back(SplitScanSelector(input).path);
    others.insert(others.end(), outputs.begin(), outputs.end());
    CheckOutputPath(output, others);
    outputs.push_back(output);
  }
  if (!json_path.empty() && json_path != "-") {
    std::vector<std::string> others = inputs;
    others.insert(others.end(), outputs.begin(), outputs.end());
    CheckOutputPath(json_path, others);
  }
  const Timer timer;
  std::vector<Scan> stations;
  for (const std::string& input : inputs) {
    const ScanFile file = ReadScanFileAndWarn(input);
    if (file.scans.empty()) throw InputError(fmt::format("register: {} holds no scan", input));
    stations.push_back(file.scans[0]);
    if (stations.back().name.empty()) stations.back().name = input;
  }
  const double reading_seconds = timer.Seconds();
  const SiteRegistration result = RegisterSite(stations, 0, icp, site);
  const Timer writing;
  for (size_t k = 1; k < stations.size(); ++k) {
    Scan moved = stations[k];
    moved.world_from_scanner = result.stations[k].world_from_scanner;
    WriteScanFile(outputs[k - 1], {moved});
  }
  SiteRegistrationSummary summary = SummarizeSiteRegistration(result, 0);
  summary.seconds.reading = reading_seconds;
  summary.seconds.writing = writing.Seconds();
  double worst_rms = 0;
  for (size_t k = 0; k < stations.size(); ++k) {
    summary.stations[k].input = inputs[k];
    if (k > 0) summary.stations[k].output = outputs[k - 1];
    worst_rms = std::max(worst_rms, result.stations[k].rms_m);
  }
  int in_graph = 0;
  for (const SitePair& pair : result.pairs) in_graph += pair.in_graph;
  summary.seconds.total = timer.Seconds();
  WriteJsonOutput(json_path, CommandJson(ToJson(RegisterSiteOptions{icp, site}), ToJson(summary)));
  Summarize(
      fmt::format("site of {} stations registered onto {}: {} pairs in the graph, worst station RMS {:.4f} "
                  "m -> {}",
                  stations.size(), fixed_path, in_graph, worst_rms, output_dir));
  return 0;
}

}  // namespace

int RunRegister(int argc, char** argv) {
  CLI::App app{
      "Register MOVING onto FIXED by point-to-plane ICP from MOVING's pose (docs/points.md); writes MOVING "
      "with its world_from_scanner corrected. With several MOVING scans, registers the whole site "
      "(docs/stations.md): pairwise ICP between overlapping stations, then a pose graph over every pair; "
      "FIXED "
      "stays and -o DIR receives each moved station under its own file name. Any input may be FILE#N (scan N "
      "of a site's file).",
      "register"};
  std::string fixed_path, output_path, json_path;
  std::vector<std::string> moving_paths;
  IcpOptions options;
  GlobalAlignOptions global;
  SiteRegistrationOptions site;
  bool use_global = false;
  OptionBinder binder(app);
  app.add_option("fixed", fixed_path, "the scan that stays (its first scan; FILE#N: scan N)")->required();
  app.add_option("moving", moving_paths, "the scan(s) to move (each its first scan; FILE#N: scan N)")
      ->required();
  app.add_option("-o,--output", output_path,
                 "the moving scan with its new pose; with several MOVING, the folder for the moved stations")
      ->required();
  AddJsonOption(app, &json_path);
  binder.Bind(&options, {.flags = {{"max_correspondence_m", "--max-distance"},
                                   {"min_correspondence_m", "--min-distance"},
                                   {"max_iterations", "--iterations"}}});
  app.add_flag("--global", use_global, "no usable pose: align FPFH features by RANSAC first")
      ->group("Global alignment (--global)");
  binder.Bind(&global, {.flags = {{"voxel_m", "--voxel"},
                                  {"feature_radius_m", "--feature-radius"},
                                  {"normal_radius_m", "--global-normal-radius"},
                                  {"inlier_distance_m", "--global-inlier-distance"},
                                  {"max_iterations", "--global-iterations"},
                                  {"edge_ratio", "--global-edge-ratio"}},
                        .group = "Global alignment (--global)",
                        .prefix = "global"});
  binder.Bind(&site, {.flags = {{"overlap_distance_m", "--overlap-distance"},
                                {"coarse_correspondence_m", "--coarse-distance"},
                                {"rotation_scale_m", "--rotation-scale"}},
                      .group = "Site (several MOVING scans)",
                      .prefix = "site"});
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(options);
        if (use_global) {
          try {
            Validate(global);
          } catch (const OptionsFieldError& error) {
            throw OptionsFieldError("global." + error.key_path(), error.reason());
          }
        }
        try {
          Validate(site);
        } catch (const OptionsFieldError& error) {
          throw OptionsFieldError("site." + error.key_path(), error.reason());
        }
        if (moving_paths.size() > 1) {
          if (use_global)
            throw OptionsError("--global registers one MOVING scan; a site starts from its poses");
          return RegisterSiteCommand(fixed_path, moving_paths, output_path, json_path, options, site);
        }
        const std::string& moving_path = moving_paths[0];
        CheckScanFileFormat(output_path);
        const std::vector<std::string> inputs = {fixed_path, moving_path, SplitScanSelector(fixed_path).path,
                                                 SplitScanSelector(moving_path).path};
        CheckOutputPath(output_path, inputs);
        if (!json_path.empty() && json_path != "-") {
          std::vector<std::string> others = inputs;
          others.push_back(output_path);
          CheckOutputPath(json_path, others);
        }
        const Timer timer;
        const ScanFile fixed = ReadScanFileAndWarn(fixed_path), moving = ReadScanFileAndWarn(moving_path);
        if (fixed.scans.empty() || moving.scans.empty()) throw InputError("register: an input holds no scan");
        const ScanRegistration result =
            RegisterScans(fixed.scans[0], moving.scans[0], options, use_global ? &global : nullptr);
        WriteScanFile(output_path, {result.registered});
        ScanRegistrationSummary summary = SummarizeScanRegistration(result, use_global ? &global : nullptr);
        summary.seconds = timer.Seconds();
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(summary)));
        Summarize(fmt::format("{} registered onto {}: RMS {:.4f} m, fitness {:.3f}, {} iterations{} -> {}",
                              moving_path, fixed_path, result.icp.rms_m, result.icp.fitness,
                              result.icp.iterations, result.icp.converged ? "" : " (not converged)",
                              output_path));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
