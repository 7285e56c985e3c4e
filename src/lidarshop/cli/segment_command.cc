// lidarshop segment: cut an object out of a scan from strokes (segment/segment.h, docs/segment.md).
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/strokes.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"

namespace lidarshop::cli {
namespace {

std::string DefaultOverlayPath(const std::string& mask_path) {
  std::filesystem::path path(mask_path);
  return (path.parent_path() / (path.stem().string() + "_overlay.png")).string();
}

}  // namespace

int RunSegment(int argc, char** argv) {
  CLI::App app{
      "Cut an object out of a scan from strokes: two-step RGB + depth graph cut (docs/segment.md).\n"
      "Strokes: a PNG of the scan image's size (green = object, red = background) or JSON polylines in grid "
      "coordinates. Writes the mask (PNG, 255 = object) and an overlay picture (mask outline and strokes "
      "over the "
      "scan's colours; default MASK_overlay.png next to the mask, --overlay none to skip).",
      "segment"};
  std::string scan_path, strokes_path, mask_path, object_path, rest_path, overlay_path, refine_path;
  std::string method = "two-step", model = "gmm";
  int scan_index = 0;
  bool eight = false, quiet = false;
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--strokes", strokes_path, "strokes: .png (green object, red background) or .json polylines")
      ->required();
  app.add_option("-o,--output", mask_path, "output mask PNG (255 = object, image orientation)")->required();
  app.add_option("--object", object_path,
                 "write the object as an organized scan here (.ptx, .e57, .ply, .pcd): grid and pose kept, "
                 "other cells without a return");
  app.add_option("--rest", rest_path, "write the rest of the scan (every cell not in the object) likewise");
  app.add_option("--overlay", overlay_path,
                 "overlay picture path (default: MASK_overlay.png; 'none' = skip)");
  app.add_option("--refine", refine_path, "extra strokes applied as a fast refinement of the first cut");
  app.add_option("--method", method, "two-step | depth | color | rgbd")->capture_default_str();
  app.add_option("--model", model, "appearance model: histogram | gmm")->capture_default_str();
  app.add_option("--scan-index", scan_index, "which scan of a multi-scan file")->capture_default_str();
  app.add_flag("--eight", eight, "8-connected n-links (default 4)");
  SegmentOptions options;
  app.add_option("--ring-threshold", options.ring_depth_threshold_m,
                 "step 2: range jump (metres) that marks a ring cell background")
      ->capture_default_str();
  app.add_option("--depth-bin", options.depth_bin_m, "range histogram bin, metres (GMM: variance floor)")
      ->capture_default_str();
  app.add_option("--depth-smoothing", options.depth_smoothing_m, "range model smoothing, metres")
      ->capture_default_str();
  AddQuietFlag(app, &quiet);
  return RunCommand(app, argc, argv, [&]() {
    options.method = ParseEnum<SegmentMethod>(method);
    options.model = ParseEnum<AppearanceModel>(model);
    options.eight_connected = eight;
    options.Check();
    for (const std::string& path : {object_path, rest_path}) {
      if (!path.empty()) CheckScanFileFormat(path);
    }
    std::vector<std::string> used = {scan_path, strokes_path, refine_path};
    for (const std::string& path : {mask_path, object_path, rest_path, overlay_path}) {
      if (path.empty()) continue;
      CheckOutputPath(path, used);
      used.push_back(path);
    }
    const ScanFile file = ReadScanFileAndWarn(scan_path);
    const Scan& scan = PickScan(file, scan_index);
    cv::Mat strokes = ReadStrokes(strokes_path, scan.rows, scan.cols);
    SegmentSession session(scan, options);
    SegmentResult result = session.Run(strokes);
    if (!quiet) fmt::print("{}: {}\n", ToString(options.method), result.Summary());
    if (!refine_path.empty()) {
      const cv::Mat extra = ReadStrokes(refine_path, scan.rows, scan.cols);
      result = session.Refine(extra);
      strokes.setTo(kStrokeObject, extra == kStrokeObject);
      strokes.setTo(kStrokeBackground, extra == kStrokeBackground);
      if (!quiet) fmt::print("refined: {}\n", result.Summary());
    }
    WriteImage(mask_path, result.mask);
    if (overlay_path != "none") {
      WriteImage(overlay_path.empty() ? DefaultOverlayPath(mask_path) : overlay_path,
                 SegmentOverlay(scan, result.mask, strokes));
    }
    if (!object_path.empty()) WriteScanFile(object_path, {MaskScan(scan, result.mask)});
    if (!rest_path.empty()) WriteScanFile(rest_path, {MaskScan(scan, result.mask == 0)});
    return 0;
  });
}

}  // namespace lidarshop::cli
