// lidarshop clean: remove what moved between the stations of a site (site/transients.h, docs/stations.md).
//
//   lidarshop clean SCAN... --out DIR [--removed-masks] [--json FILE|-]
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/cli/scan_selector.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/site/transients.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {
namespace {
// The formats that keep a station's grid and pose, which the comparison of stations needs back.
const std::vector<std::string> kStationExtensions = {"ptx", "e57", "ply", "pcd"};

// DIR/<stem>_removed.png, or DIR/<stem>_<N>_removed.png for scan N of a file of several.
std::string MaskPath(const std::string& out_dir, const std::string& stem, size_t scan, size_t scans_in_file) {
  const std::string name =
      scans_in_file > 1 ? fmt::format("{}_{}_removed.png", stem, scan) : stem + "_removed.png";
  return (std::filesystem::path(out_dir) / name).string();
}
}  // namespace

int RunClean(int argc, char** argv) {
  CLI::App app{
      "Remove what moved between stations (docs/stations.md): a point of one station that the rays of "
      "another "
      "passed through, hitting something farther, is transient (a passer-by, a car that left); it is removed "
      "and its hole filled, first with what the other stations measured there (marked from_station), the "
      "rest synthesized (marked). The stations must be registered (their poses in one world "
      "frame). Every scan of every input is a station (a site's E57 holds several; FILE#N one of them); each "
      "input is written to DIR under its own name (FILE#N as FILE's stem_N).",
      "clean"};
  std::vector<std::string> inputs;
  std::string out_dir, json_path;
  bool removed_masks = false, quiet = false;
  CleanOptions options;
  OptionBinder binder(app);
  app.add_option("scans", inputs, "the stations' scan files (.e57 with several scans, .ptx, .ply, .pcd)")
      ->required();
  app.add_option("--out", out_dir, "folder for the cleaned stations (created if missing)")->required();
  app.add_flag(
      "--removed-masks", removed_masks,
      "also write DIR/<stem>_removed.png per station (<stem>_<N>_removed.png for scan N of a file "
      "with several): 1 + the index of the station that saw through each removed point, 0 elsewhere");
  AddJsonOption(app, &json_path);
  binder.Bind(&options, {.keys = {"transients.range_noise_sigma_m", "transients.min_margin_m",
                                  "transients.neighbourhood_cells", "transients.min_region_cells",
                                  "transients.grow_cells", "margin_cells", "fill_holes", "from_stations"},
                         .flags = {{"transients.range_noise_sigma_m", "--range-noise"},
                                   {"transients.min_margin_m", "--min-margin"},
                                   {"transients.neighbourhood_cells", "--neighbourhood"},
                                   {"transients.min_region_cells", "--min-region"},
                                   {"transients.grow_cells", "--grow"},
                                   {"margin_cells", "--margin"},
                                   {"fill_holes", "--fill"}}});
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(options);
        namespace fs = std::filesystem;
        std::vector<ScanFile> files;
        std::vector<Scan> stations;
        for (const std::string& path : inputs) {
          files.push_back(ReadScanFileAndWarn(path));
          for (const Scan& scan : files.back().scans) stations.push_back(scan);
        }
        std::error_code error;
        fs::create_directories(out_dir, error);
        if (error || !fs::is_directory(out_dir))
          throw InputError(fmt::format("--out {}: cannot create the folder", out_dir));
        std::vector<std::string> outputs;
        for (const std::string& path : inputs) {
          const std::string output = (fs::path(out_dir) / StationOutputName(path)).string();
          CheckOutputFile("--out", output, kStationExtensions, inputs);
          outputs.push_back(output);
        }
        // Every output is checked before the long work.
        for (size_t f = 0; f < files.size() && removed_masks; ++f) {
          const std::string stem = fs::path(StationOutputName(inputs[f])).stem().string();
          for (size_t s = 0; s < files[f].scans.size(); ++s)
            CheckOutputFile("--removed-masks", MaskPath(out_dir, stem, s, files[f].scans.size()), {"png"},
                            inputs);
        }
        const int64_t pairs =
            static_cast<int64_t>(stations.size()) * (static_cast<int64_t>(stations.size()) - 1);
        auto progress = Progress::ForTerminal("clean", pairs, quiet);
        const CleanResult result = CleanStations(stations, options, progress.get());
        if (progress) progress->Finish();
        CleanSummary summary = SummarizeClean(stations, result);
        size_t next = 0;
        for (size_t f = 0; f < files.size(); ++f) {
          std::vector<Scan> cleaned;
          for (size_t s = 0; s < files[f].scans.size(); ++s, ++next) {
            cleaned.push_back(result.stations[next]);
            CleanStationSummary& station = summary.stations[next];
            station.file = inputs[f];
            station.scan = s;
            station.output = outputs[f];
            if (removed_masks) {
              const std::string stem = fs::path(StationOutputName(inputs[f])).stem().string();
              station.removed_mask = MaskPath(out_dir, stem, s, files[f].scans.size());
              WriteImage(station.removed_mask, result.transients.stations[next].seen_through_by);
            }
          }
          WriteScanFile(outputs[f], cleaned);
        }
        PrintResultWarnings(result.warnings);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(summary)));
        Summarize(fmt::format("{} stations: {} transient points removed -> {}", stations.size(),
                              summary.removed, out_dir));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
