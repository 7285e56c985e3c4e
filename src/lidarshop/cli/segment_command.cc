// lidarshop segment: cut an object out of a scan from strokes (segment/segment.h, docs/segment.md).
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/strokes.h"
#include "lidarshop/segment/segment.h"
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
      "Strokes: painted on a picture `lidarshop render` wrote of the scan (any width; green = object, red = "
      "background), on a PNG of the scan's grid size, or JSON polylines in grid coordinates. Writes the mask "
      "(PNG, 255 = object, the scan's grid) and an overlay picture (mask outline and strokes over the scan's "
      "colours, in render's layout; default MASK_overlay.png next to the mask, --overlay none to skip).",
      "segment"};
  std::string scan_path, strokes_path, mask_path, object_path, rest_path, overlay_path, refine_path,
      json_path, layout_path;
  int scan_index = 0;
  bool quiet = false;
  SegmentOptions options;
  OptionBinder binder(app);
  app.add_option("scan", scan_path, "scan file (.ptx, .e57, .pcd, .ply with grid)")->required();
  app.add_option("--strokes", strokes_path,
                 "strokes: .png painted on a `render` picture or on the grid (green object, red background), "
                 "or .json polylines")
      ->required();
  app.add_option(
      "--layout", layout_path,
      "the layout file of the picture the strokes (and --refine) were painted on (default: "
      "STROKES.png.layout.json when it exists, else render's default layout at the picture's width)");
  app.add_option("-o,--output", mask_path, "output mask PNG (255 = object, image orientation)")->required();
  app.add_option("--object", object_path,
                 "write the object as an organized scan here (.ptx, .e57, .ply, .pcd): grid and pose kept, "
                 "other cells without a return");
  app.add_option("--rest", rest_path, "write the rest of the scan (every cell not in the object) likewise");
  app.add_option("--overlay", overlay_path,
                 "overlay picture path (default: MASK_overlay.png; 'none' = skip)");
  app.add_option("--refine", refine_path, "extra strokes applied as a fast refinement of the first cut");
  AddJsonOption(app, &json_path);
  AddScanIndexOption(app, &scan_index, "which scan of a multi-scan file (from 0)");
  binder.Bind(&options, {.flags = {{"eight_connected", "--eight"},
                                   {"ring_depth_threshold_m", "--ring-threshold"},
                                   {"depth_bin_m", "--depth-bin"},
                                   {"depth_smoothing_m", "--depth-smoothing"}}});
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&]() {
        binder.Validate(options);
        for (const std::string& path : {object_path, rest_path}) {
          if (!path.empty()) CheckScanFileFormat(path);
        }
        std::vector<std::string> used = {scan_path, strokes_path, refine_path, layout_path};
        for (const std::string& path : {mask_path, object_path, rest_path, overlay_path, json_path}) {
          if (path == "-" || path == "none") continue;
          if (path.empty()) continue;
          CheckOutputPath(path, used);
          used.push_back(path);
        }
        const ScanFile file = ReadScanFileAndWarn(scan_path);
        const Scan& scan = PickScan(file, scan_index, ScanIndexFlag(app));
        PaintedStrokes painted = ReadStrokesForScan(strokes_path, scan, layout_path, scan_path);
        cv::Mat& strokes = painted.cells;
        if (!quiet) fmt::print(stderr, "{}\n", painted.Describe());
        SegmentSession session(scan, options);
        SegmentResult result = session.Run(strokes);
        if (!quiet && !refine_path.empty())
          fmt::print(stderr, "{}: {}\n", ToString(options.method), result.Summary());
        if (!refine_path.empty()) {
          const PaintedStrokes extra = ReadStrokesForScan(refine_path, scan, layout_path, scan_path);
          result = session.Refine(extra.cells);
          strokes.setTo(kStrokeObject, extra.cells == kStrokeObject);
          strokes.setTo(kStrokeBackground, extra.cells == kStrokeBackground);
          // Both painted on the same picture: the overlay shows both as painted; else the cells.
          if (!painted.picture.empty() && !extra.picture.empty() &&
              painted.picture.size() == extra.picture.size()) {
            painted.picture.setTo(kStrokeObject, extra.picture == kStrokeObject);
            painted.picture.setTo(kStrokeBackground, extra.picture == kStrokeBackground);
          } else {
            painted.picture.release();
            painted.mapping.reset();
          }
        }
        PrintResultWarnings(result.warnings);
        Summarize(fmt::format("{}{}: {} -> {}", ToString(options.method),
                              refine_path.empty() ? "" : ", refined", result.Summary(), mask_path));
        WriteImage(mask_path, result.mask);
        if (overlay_path != "none") {
          WriteImage(overlay_path.empty() ? DefaultOverlayPath(mask_path) : overlay_path,
                     OverlayOnPicture(scan, result.mask, painted));
        }
        if (!object_path.empty()) WriteScanFile(object_path, {MaskScan(scan, result.mask)});
        if (!rest_path.empty()) WriteScanFile(rest_path, {MaskScan(scan, result.mask == 0)});
        result.refined = !refine_path.empty();
        WriteJsonOutput(json_path, CommandJson(ToJson(options), ToJson(result)));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
