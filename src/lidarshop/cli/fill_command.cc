// lidarshop fill / remove: fill holes in scans, remove objects (fill/fill.h, docs/fill.md).
//
//   lidarshop fill SCAN --mask HOLE.png -o OUT [--method gradient|laplace|depth-patch|telea]
//                  [--json R.json] [--debug DIR] [--seed N] [--synthesized-mask M.png]
//   lidarshop remove SCAN --strokes S -o OUT [--keep-object] [--margin CELLS]
//   both with --stations OTHER... [--from-stations-mask M.png]: the hole filled first from what the other
//   stations of the site measured behind the object (site/from_stations.h), the rest synthesized.
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/image/colormap.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/render/picture_mapping.h"
#include "lidarshop/render/strokes.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {
namespace {

// The fill options every fill command shares, bound to flags from their description (fill/fill.h).
// `prefix`: their key path inside the command's options ("fill" in remove).
void BindFillOptions(OptionBinder& binder, FillOptions* options, const std::string& prefix = "") {
  binder.Bind(
      options,
      {.skip = {"telea_radius_cells"}, .flags = {{"search_window_radius", "--window"}}, .prefix = prefix});
  binder.Bind(options,
              {.keys = {"acceptance.enabled", "planes.enabled", "lattice.enabled", "telea_radius_cells"},
               .flags = {{"acceptance.enabled", "--accept"},
                         {"planes.enabled", "--planes"},
                         {"lattice.enabled", "--lattice"}},
               .prefix = prefix});
}

// Outputs are checked before the long work: a scan format, a folder that exists, never an input.
const std::vector<std::string> kScanExtensions = {"ptx", "e57", "ply", "pcd"};

// Pictures of the fill's inner workings: gradient magnitude before and after, fill order, source cells.
void WriteDebug(const std::string& dir, const FillResult& result, const cv::Mat& hole) {
  std::filesystem::create_directories(dir);
  WriteImage(dir + "/hole.png", hole);
  if (result.gradient_magnitude_before.empty()) return;
  const cv::Mat everywhere(hole.size(), CV_8U, cv::Scalar(255));
  const ColorScale scale =
      AutoScale(result.gradient_magnitude_after, everywhere, ColorMap::kViridis, "m/cell");
  WriteImage(dir + "/gradient_before.png", ApplyColorMap(result.gradient_magnitude_before, hole == 0, scale));
  WriteImage(dir + "/gradient_after.png", ApplyColorMap(result.gradient_magnitude_after, everywhere, scale));
  if (!result.fill_order.empty()) {
    cv::Mat order;
    result.fill_order.convertTo(order, CV_32F);
    const cv::Mat filled = result.fill_order >= 0;
    WriteImage(dir + "/fill_order.png",
               ApplyColorMap(order, filled, AutoScale(order, filled, ColorMap::kViridis, "patch")));
  }
  if (!result.source_cell.empty()) {
    // Each hole cell coloured by where it came from: red = source column, green = source row.
    cv::Mat sources(hole.size(), CV_8UC3, cv::Scalar::all(0));
    for (int y = 0; y < hole.rows; ++y) {
      for (int x = 0; x < hole.cols; ++x) {
        const cv::Vec2i s = result.source_cell.at<cv::Vec2i>(y, x);
        if (s[0] < 0) continue;
        sources.at<cv::Vec3b>(y, x) =
            cv::Vec3b(static_cast<uint8_t>(255 * s[1] / std::max(1, hole.cols - 1)),
                      static_cast<uint8_t>(255 * s[0] / std::max(1, hole.rows - 1)), 96);
      }
    }
    WriteImage(dir + "/source_cells.png", sources);
  }
}

// Formats that cannot hold Scan::from_station (PTX) say so: the cells taken from other stations are written
// as plain returns.
void WarnFromStationDropped(const std::string& path, const Scan& scan) {
  if (scan.from_station.empty()) return;
  for (const std::string& sentence : PlanScanWrite(path, {scan}, 0, 0).dropped)
    if (sentence.find("from_station") != std::string::npos) PrintWarnings({sentence});
}

// --stations and --from-stations-mask, shared by fill and remove.
struct StationFlags {
  std::vector<std::string> paths;
  std::string mask_path;
  FromStationsOptions options;

  void Add(CLI::App& app, OptionBinder& binder) {
    app.add_option(
           "--stations", paths,
           "other stations of the site, registered with the scan (their poses in one world frame): "
           "FILE#N for scan N of a file of several, every scan of FILE otherwise (the scan itself is "
           "left out when listed). The hole is filled first with what they measured behind the object "
           "(marked from_station, not synthesized); only what no station saw is synthesized")
        ->group("Fill from other stations");
    app.add_option("--from-stations-mask", mask_path,
                   "with --stations: write the cells filled from another station's measurement as a mask PNG "
                   "of the scan's grid (255 = from a station)")
        ->group("Fill from other stations");
    binder.Bind(&options, {.keys = {"range_noise_sigma_m", "min_margin_m", "check_free_space"},
                           .flags = {{"range_noise_sigma_m", "--station-noise"},
                                     {"min_margin_m", "--station-margin"},
                                     {"check_free_space", "--free-space"}},
                           .group = "Fill from other stations",
                           .prefix = "from_stations"});
  }

  // Every scan of the files given, but the scan being filled (same pose and grid size), and where each came
  // from: its file and index there (FromStationsSource's file and scan).
  std::vector<Scan> Read(const Scan& scan, std::vector<FromStationsSource>* sources) const {
    std::vector<Scan> stations;
    for (const std::string& path : paths) {
      const ScanFile file = ReadScanFileAndWarn(path);
      for (size_t i = 0; i < file.scans.size(); ++i) {
        const Scan& other = file.scans[i];
        if (other.rows == scan.rows && other.cols == scan.cols &&
            other.world_from_scanner == scan.world_from_scanner)
          continue;
        stations.push_back(other);
        sources->push_back({.file = path, .scan = static_cast<int64_t>(i)});
      }
    }
    if (stations.empty())
      throw InputError(
          fmt::format("--stations: {} hold(s) no station other than the scan", fmt::join(paths, ", ")));
    return stations;
  }
};

// The files and indices the stations were read from (StationFlags::Read), into the result's stations.
void SetStationFiles(const std::vector<FromStationsSource>& sources, FromStationsResult* result) {
  for (size_t k = 0; k < result->stations.size(); ++k) {
    result->stations[k].file = sources.at(k).file;
    result->stations[k].scan = sources.at(k).scan;
  }
}

std::string FromStationsSummary(const FromStationsResult& result) {
  return fmt::format("{} hole cells: {} from other stations, {} synthesized, {} without a return",
                     result.hole_cells, result.from_station_cells, result.synthesized_cells,
                     result.no_return_cells);
}

}  // namespace

int RunFill(int argc, char** argv) {
  CLI::App app{
      "Fill a hole in a scan (docs/fill.md): inpaint the range gradients guided by colour, reconstruct range "
      "with Poisson, place the points along the scanner's rays and flag them synthesized. Every cell outside "
      "the mask is copied bit for bit.",
      "fill"};
  std::string scan_path, mask_path, output_path, json_path, debug_dir, synthesized_mask_path, layout_path;
  int scan_index = 0;
  bool quiet = false;
  FillOptions options;
  OptionBinder binder(app);
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--mask", mask_path,
                 "hole mask PNG, white = fill: of the scan's grid size (cols x rows) or painted on a picture "
                 "`lidarshop render` wrote of the scan (any width)")
      ->required();
  app.add_option("--layout", layout_path,
                 "the layout file of the picture the mask was painted on (default: MASK.png.layout.json when "
                 "it exists, else render's default layout at the picture's width)");
  app.add_option("-o,--output", output_path, "filled scan (.ptx, .e57, .ply, .pcd): same grid and pose")
      ->required();
  AddJsonOption(app, &json_path, "--json,--report");
  app.add_option("--debug", debug_dir,
                 "write gradient magnitude before/after, fill order and source cells here");
  app.add_option("--synthesized-mask", synthesized_mask_path, "write the synthesized cells as a mask PNG");
  AddScanIndexOption(app, &scan_index, "which scan of a multi-scan file (from 0)");
  BindFillOptions(binder, &options);
  StationFlags stations;
  stations.Add(app, binder);
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(options);
        binder.Validate(stations.options);
        std::vector<std::string> inputs = {scan_path, mask_path};
        inputs.insert(inputs.end(), stations.paths.begin(), stations.paths.end());
        CheckOutputFile("-o", output_path, kScanExtensions, inputs);
        inputs.push_back(output_path);
        CheckOutputFile("--json", json_path, {}, inputs);
        inputs.push_back(json_path);
        CheckOutputFile("--synthesized-mask", synthesized_mask_path, {"png"}, inputs);
        inputs.push_back(synthesized_mask_path);
        if (!stations.mask_path.empty() && stations.paths.empty())
          throw OptionsError("--from-stations-mask needs --stations");
        CheckOutputFile("--from-stations-mask", stations.mask_path, {"png"}, inputs);
        const ScanFile file = ReadScanFileAndWarn(scan_path);
        const Scan& scan = PickScan(file, scan_index, ScanIndexFlag(app));
        const cv::Mat hole = ReadMaskForScan(mask_path, scan, layout_path, scan_path);
        if (!stations.paths.empty()) {
          std::vector<FromStationsSource> sources;
          const std::vector<Scan> others = stations.Read(scan, &sources);
          stations.options.fill = options;
          auto progress = Progress::ForTerminal(
              "fill from stations", static_cast<int64_t>(others.size()) + cv::countNonZero(hole) / 4096 + 1,
              quiet);
          FromStationsResult result = FillFromStations(scan, hole, others, stations.options, progress.get());
          SetStationFiles(sources, &result);
          if (progress) progress->Finish();
          WriteScanFile(output_path, {result.scan});
          WarnFromStationDropped(output_path, result.scan);
          if (!synthesized_mask_path.empty()) WriteImage(synthesized_mask_path, result.synthesized);
          if (!stations.mask_path.empty()) WriteImage(stations.mask_path, result.from_station != 0);
          const FillWithStationsOptions used{.fill = options, .from_stations = stations.options};
          WriteJsonOutput(json_path, CommandJson(ToJson(used), ToJson(result)));
          if (!debug_dir.empty() && result.filled_rest) WriteDebug(debug_dir, result.fill, hole);
          PrintResultWarnings(result.warnings);
          Summarize(fmt::format("{} -> {}", FromStationsSummary(result), output_path));
          return 0;
        }
        auto progress = Progress::ForTerminal("fill", cv::countNonZero(hole), quiet);
        // The fill's window pasted into the scan read here: no copy of the whole scan (FillScanWindow).
        FillResult result = FillScanWindow(scan, hole, options, progress.get());
        if (progress) progress->Finish();
        Scan filled = scan;  // shares the file's buffers, which nothing else reads
        ApplyFill(result, &filled);
        WriteScanFile(output_path, {filled});
        WarnFromStationDropped(output_path, filled);
        if (!synthesized_mask_path.empty() || !debug_dir.empty())
          PadFillImages(scan.rows, scan.cols, &result);
        if (!synthesized_mask_path.empty()) WriteImage(synthesized_mask_path, result.filled);
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(result)));
        if (!debug_dir.empty()) WriteDebug(debug_dir, result, hole);
        PrintResultWarnings(result.warnings);
        Summarize(fmt::format("{} -> {}", result.Summary(), output_path));
        return 0;
      },
      &binder);
}

int RunRemove(int argc, char** argv) {
  CLI::App app{
      "Remove an object from a scan (docs/fill.md): cut it out from two strokes (two-step graph cut, as "
      "`segment`), then fill its cells grown by a margin. With --keep-object the object stays and the filled "
      "background is added behind it as a second layer.",
      "remove"};
  std::string scan_path, strokes_path, output_path, mask_out_path, json_path, layout_path;
  int scan_index = 0;
  bool quiet = false;
  RemoveOptions remove;
  OptionBinder binder(app);
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--strokes", strokes_path,
                 "strokes: .png painted on a `render` picture or on the grid (green object, red background), "
                 "or .json polylines")
      ->required();
  app.add_option(
      "--layout", layout_path,
      "the layout file of the picture the strokes were painted on (default: STROKES.png.layout.json "
      "when it exists, else render's default layout at the picture's width)");
  app.add_option("-o,--output", output_path, "the scan without the object (.ptx, .e57, .ply, .pcd)")
      ->required();
  app.add_option("--mask-out", mask_out_path,
                 "write the filled hole (object grown by the margin) as a mask PNG");
  AddJsonOption(app, &json_path, "--json,--report");
  AddScanIndexOption(app, &scan_index, "which scan of a multi-scan file (from 0)");
  // --keep-object: E57 holds the fill as a second return, PLY/PCD as extra points flagged synthesized.
  binder.Bind(&remove, {.keys = {"margin_cells", "keep_object", "fill_enclosed_no_return"},
                        .flags = {{"margin_cells", "--margin"}}});
  BindFillOptions(binder, &remove.fill, "fill");
  StationFlags stations;
  stations.Add(app, binder);
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(remove);
        binder.Validate(stations.options);
        std::vector<std::string> inputs = {scan_path, strokes_path};
        inputs.insert(inputs.end(), stations.paths.begin(), stations.paths.end());
        CheckOutputFile("-o", output_path, kScanExtensions, inputs);
        if (const ScanFormatInfo* format = FindScanFormat(FileExtension(output_path));
            remove.keep_object && format != nullptr && !format->layer_behind) {
          throw OptionsError("--keep-object: " + LayerBehindRefusal(*format));
        }
        inputs.push_back(output_path);
        CheckOutputFile("--mask-out", mask_out_path, {"png"}, inputs);
        inputs.push_back(mask_out_path);
        CheckOutputFile("--json", json_path, {}, inputs);
        inputs.push_back(json_path);
        if (!stations.mask_path.empty() && stations.paths.empty())
          throw OptionsError("--from-stations-mask needs --stations");
        CheckOutputFile("--from-stations-mask", stations.mask_path, {"png"}, inputs);
        const ScanFile file = ReadScanFileAndWarn(scan_path);
        const Scan& scan = PickScan(file, scan_index, ScanIndexFlag(app));
        const PaintedStrokes painted = ReadStrokesForScan(strokes_path, scan, layout_path, scan_path);
        const cv::Mat& strokes = painted.cells;
        if (!quiet) fmt::print(stderr, "{}\n", painted.Describe());
        if (!stations.paths.empty()) {
          std::vector<FromStationsSource> sources;
          const std::vector<Scan> others = stations.Read(scan, &sources);
          auto progress =
              Progress::ForTerminal("remove from stations", static_cast<int64_t>(others.size()) + 1, quiet);
          RemoveFromStationsResult removed =
              RemoveObjectFromStations(scan, strokes, others, remove, stations.options, progress.get());
          SetStationFiles(sources, &removed.filled);
          if (progress) progress->Finish();
          if (!quiet) fmt::print(stderr, "segment: {}\n", removed.cut.Summary());
          if (remove.keep_object) {
            WriteScanWithLayer(output_path, scan, removed.behind);
          } else {
            WriteScanFile(output_path, {removed.filled.scan});
            WarnFromStationDropped(output_path, removed.filled.scan);
          }
          if (!mask_out_path.empty()) WriteImage(mask_out_path, removed.hole);
          if (!stations.mask_path.empty()) WriteImage(stations.mask_path, removed.filled.from_station != 0);
          const RemoveWithStationsOptions used{.remove = remove, .from_stations = stations.options};
          WriteJsonOutput(json_path, CommandJson(ToJson(used), ToJson(removed)));
          PrintResultWarnings(removed.warnings);
          Summarize(fmt::format("removed {} cells: {} -> {}", cv::countNonZero(removed.hole),
                                FromStationsSummary(removed.filled), output_path));
          return 0;
        }
        auto progress = Progress::ForTerminal("segment", 1, quiet);  // RemoveObject restarts it for the fill
        const RemoveResult removed = RemoveObjectWindow(scan, strokes, remove, progress.get());
        if (progress) progress->Finish();
        const FillResult& result = removed.fill;
        const cv::Mat& hole = removed.hole;
        if (!quiet) fmt::print(stderr, "segment: {}\n", removed.cut.Summary());
        if (remove.keep_object) {
          WriteScanWithLayer(output_path, scan, removed.behind);
        } else {
          Scan without = scan;  // shares the file's buffers, which nothing reads after this
          ApplyFill(result, &without);
          WriteScanFile(output_path, {without});
          WarnFromStationDropped(output_path, without);
        }
        if (!mask_out_path.empty()) WriteImage(mask_out_path, hole);
        WriteJsonOutput(json_path, CommandJson(ToJson(remove), ToJson(removed)));
        PrintResultWarnings(removed.warnings);
        Summarize(
            fmt::format("removed {} cells: {} -> {}", cv::countNonZero(hole), result.Summary(), output_path));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
