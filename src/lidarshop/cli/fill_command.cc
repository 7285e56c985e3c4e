// lidarshop fill / remove: fill holes in scans, remove objects (fill/fill.h, docs/fill.md).
//
//   lidarshop fill SCAN --mask HOLE.png -o OUT [--method gradient|laplace|depth-patch|telea]
//                  [--report R.json] [--debug DIR] [--seed N] [--synthesized-mask M.png]
//   lidarshop remove SCAN --strokes S -o OUT [--keep-object] [--margin CELLS]
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/image/colormap.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/strokes.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {
namespace {

// The fill options every fill command shares, bound to flags.
struct FillFlags {
  std::string method = "gradient", search = "patchmatch";
  bool no_accept = false;
  FillOptions options;
  void Add(CLI::App& app) {
    app.add_option("--method", method, "gradient | laplace | depth-patch | telea")->capture_default_str();
    app.add_option("--search", search, "source search of the patch methods: patchmatch | local | exhaustive")
        ->capture_default_str();
    AddSeedOption(app, &options.seed, "seed of the patch fill's random choices");
    app.add_option("--patch-radius", options.patch_radius, "patch half-width, cells")->capture_default_str();
    app.add_option("--window", options.search_window_radius, "half-width of the local source search, cells")
        ->capture_default_str();
    app.add_option("--color-weight", options.color_weight, "patch difference weight of the colour channels")
        ->capture_default_str();
    app.add_option("--gradient-weight", options.gradient_weight,
                   "patch difference weight of the range-gradient channels")
        ->capture_default_str();
    app.add_option("--return-weight", options.return_weight,
                   "patch difference weight of the has-return channel")
        ->capture_default_str();
    app.add_flag("--no-accept", no_accept,
                 "copy the best patch without the acceptance tests (faster; worse where surfaces meet)");
  }
  FillOptions Parsed() {
    options.method = ParseEnum<FillMethod>(method);
    if (no_accept) options.acceptance.enabled = false;
    if (search == "patchmatch") {
      options.search = InpaintSearchKind::kPatchMatch;
    } else if (search == "local") {
      options.search = InpaintSearchKind::kLocal;
    } else if (search == "exhaustive") {
      options.search = InpaintSearchKind::kTwoStep;  // exact, with the local window as the first bound
    } else {
      throw OptionsError(fmt::format("--search '{}': expected patchmatch, local or exhaustive", search));
    }
    options.Check();
    return options;
  }
};

// Outputs are checked before the long work: a scan format, a folder that exists, never an input.
void CheckScanOutput(const std::string& output, const std::vector<std::string>& inputs) {
  const std::string extension = FileExtension(output);
  if (extension != "ptx" && extension != "e57" && extension != "ply" && extension != "pcd") {
    throw OptionsError(fmt::format("-o {}: the output must be a scan file (.ptx, .e57, .ply, .pcd)", output));
  }
  CheckOutputPath(output, inputs);
}

nlohmann::json ReportJson(const FillResult& result, const FillOptions& options) {
  return {{"method", ToString(options.method)},
          {"seed", options.seed},
          {"patch_radius_cells", options.patch_radius},
          {"hole_cells", result.hole_cells},
          {"synthesized_points", result.synthesized_cells},
          {"no_return_cells", result.no_return_cells},
          {"unanchored_cells", result.unanchored_cells},
          {"patches", result.patches},
          {"candidates_evaluated", result.candidates_evaluated},
          {"seconds",
           {{"gradients", result.timings.gradients_s},
            {"inpaint", result.timings.inpaint_s},
            {"poisson", result.timings.poisson_s},
            {"placement", result.timings.placement_s},
            {"total", result.timings.total_s}}}};
}

void WriteJson(const std::string& path, const nlohmann::json& json) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

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

}  // namespace

int RunFill(int argc, char** argv) {
  CLI::App app{
      "Fill a hole in a scan (docs/fill.md): inpaint the range gradients guided by colour, reconstruct range "
      "with Poisson, place the points along the scanner's rays and flag them synthesized. Every cell outside "
      "the mask is copied bit for bit.",
      "fill"};
  std::string scan_path, mask_path, output_path, report_path, debug_dir, synthesized_mask_path;
  int scan_index = 0;
  bool quiet = false;
  FillFlags flags;
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--mask", mask_path, "hole mask PNG, scan image orientation (cols x rows), white = fill")
      ->required();
  app.add_option("-o,--output", output_path, "filled scan (.ptx, .e57, .ply, .pcd): same grid and pose")
      ->required();
  app.add_option("--report", report_path, "write counts and timings as JSON");
  app.add_option("--debug", debug_dir,
                 "write gradient magnitude before/after, fill order and source cells here");
  app.add_option("--synthesized-mask", synthesized_mask_path, "write the synthesized cells as a mask PNG");
  app.add_option("--scan-index", scan_index, "which scan of a multi-scan file")->capture_default_str();
  flags.Add(app);
  AddQuietFlag(app, &quiet);
  return RunCommand(app, argc, argv, [&]() {
    const FillOptions options = flags.Parsed();
    CheckScanOutput(output_path, {scan_path, mask_path});
    for (const std::string& path : {report_path, synthesized_mask_path}) {
      if (!path.empty()) CheckOutputPath(path, {scan_path, mask_path, output_path});
    }
    const ScanFile file = ReadScanFile(scan_path);
    const Scan& scan = PickScan(file, scan_index);
    const cv::Mat hole = ReadMask(mask_path, cv::Size(scan.cols, scan.rows), scan_path);
    auto progress = Progress::ForTerminal("fill", cv::countNonZero(hole), quiet);
    const FillResult result = FillScan(scan, hole, options, progress.get());
    if (progress) progress->Finish();
    WriteScanFile(output_path, {result.scan});
    if (!synthesized_mask_path.empty()) WriteImage(synthesized_mask_path, result.filled);
    if (!report_path.empty()) WriteJson(report_path, ReportJson(result, options));
    if (!debug_dir.empty()) WriteDebug(debug_dir, result, hole);
    if (!quiet) fmt::print(stderr, "{}\n", result.Summary());
    return 0;
  });
}

int RunRemove(int argc, char** argv) {
  CLI::App app{
      "Remove an object from a scan (docs/fill.md): cut it out from two strokes (two-step graph cut, as "
      "`segment`), then fill its cells grown by a margin. With --keep-object the object stays and the filled "
      "background is added behind it as a second layer.",
      "remove"};
  std::string scan_path, strokes_path, output_path, mask_out_path, report_path;
  int scan_index = 0, margin = 2;
  bool keep_object = false, quiet = false;
  FillFlags flags;
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--strokes", strokes_path, "strokes: .png (green object, red background) or .json polylines")
      ->required();
  app.add_option("-o,--output", output_path, "the scan without the object (.ptx, .e57, .ply, .pcd)")
      ->required();
  app.add_flag("--keep-object", keep_object,
               "keep the object; add the filled background behind it (E57: second return; PLY/PCD: extra "
               "points flagged synthesized; PTX cannot hold it)");
  app.add_option("--margin", margin,
                 "grow the object's cells by this many cells (mixed pixels at its silhouette)")
      ->capture_default_str();
  app.add_option("--mask-out", mask_out_path,
                 "write the filled hole (object grown by the margin) as a mask PNG");
  app.add_option("--report", report_path, "write counts and timings as JSON");
  app.add_option("--scan-index", scan_index, "which scan of a multi-scan file")->capture_default_str();
  flags.Add(app);
  AddQuietFlag(app, &quiet);
  return RunCommand(app, argc, argv, [&]() {
    const FillOptions options = flags.Parsed();
    CheckScanOutput(output_path, {scan_path, strokes_path});
    if (keep_object && FileExtension(output_path) == "ptx") {
      throw OptionsError(
          "--keep-object: PTX cannot hold two returns per cell; write the two layers as .e57, .ply or .pcd");
    }
    for (const std::string& path : {mask_out_path, report_path}) {
      if (!path.empty()) CheckOutputPath(path, {scan_path, strokes_path, output_path});
    }
    const ScanFile file = ReadScanFile(scan_path);
    const Scan& scan = PickScan(file, scan_index);
    const cv::Mat strokes = ReadStrokes(strokes_path, scan.rows, scan.cols);
    RemoveOptions remove;
    remove.fill = options;
    remove.margin_cells = margin;
    remove.keep_object = keep_object;
    auto progress = Progress::ForTerminal("segment", 1, quiet);  // RemoveObject restarts it for the fill
    const RemoveResult removed = RemoveObject(scan, strokes, remove, progress.get());
    if (progress) progress->Finish();
    const FillResult& result = removed.fill;
    const cv::Mat& hole = removed.hole;
    if (!quiet) fmt::print(stderr, "segment: {}\n", removed.cut.Summary());
    if (keep_object) {
      WriteScanWithLayer(output_path, scan, removed.behind);
    } else {
      WriteScanFile(output_path, {result.scan});
    }
    if (!mask_out_path.empty()) WriteImage(mask_out_path, hole);
    if (!report_path.empty()) {
      nlohmann::json report = ReportJson(result, options);
      report["object_cells"] = removed.cut.object_cells;
      report["margin_cells"] = margin;
      report["keep_object"] = keep_object;
      WriteJson(report_path, report);
    }
    if (!quiet) fmt::print(stderr, "{}\n", result.Summary());
    return 0;
  });
}

}  // namespace lidarshop::cli
