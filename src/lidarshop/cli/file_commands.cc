// lidarshop info | convert | render: describe, convert and picture scan files.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/cli/scan_selector.h"
#include "lidarshop/image/colormap.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_summary.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/pointset/ground.h"
#include "lidarshop/recolor/e57_camera.h"
#include "lidarshop/render/picture_mapping.h"
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/render_view.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {
namespace {

// `convert --synthesized-mask`: the scan's grid, 255 where a return is synthesized.
void WriteSynthesizedMask(const std::string& path, const Scan& scan) {
  // libpng refuses to write images wider than a million pixels (its default user limit).
  constexpr int kPngMaxWidth = 1000000;
  if (scan.cols > kPngMaxWidth) {
    throw OptionsError(
        fmt::format("--synthesized-mask {}: the scan is {} cells wide, more than PNG's {}; "
                    "use --drop-synthesized or write LAS, PLY, PCD or E57, which mark them",
                    path, scan.cols, kPngMaxWidth));
  }
  cv::Mat mask(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  if (!scan.synthesized.empty()) mask.setTo(255, (scan.synthesized != 0) & (scan.valid != 0));
  WriteImage(path, mask);
}

// FILE#N given to `info`: only scan N of the listing, no stations; OptionsError when out of range.
template <class Summary>
void KeepOnlyScan(const ScanSelector& selector, Summary* summary) {
  if (selector.index < 0) return;
  if (selector.index >= static_cast<int>(summary->scans.size())) {
    throw OptionsError(fmt::format("{}#{}: scan {} is out of range: {} holds {} scan(s), numbered from 0",
                                   selector.path, selector.index, selector.index, selector.path,
                                   summary->scans.size()));
  }
  summary->scans = {summary->scans[selector.index]};
  summary->stations.clear();
}

}  // namespace

int RunInfo(int argc, char** argv) {
  CLI::App app{
      "Describe a scan file (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts) as one JSON object (on stdout unless "
      "--json): format, size, scans (organized or not, rows x cols, points, channels, pose, E57 sensor and "
      "dates), E57 images. Reads the headers only (XYZ/PTS have none: they are read whole); --stats reads "
      "the "
      "points too.",
      "info"};
  std::string path, json_path = "-";
  bool compact = false, stats = false;
  app.add_option("file", path, "scan file (FILE#N: scan N alone)")->required();
  AddJsonOption(app, &json_path);
  app.add_flag("--compact", compact, "write the JSON on one line");
  app.add_flag("--stats", stats,
               "also read every point: per scan the valid returns, world bounds, range and intensity "
               "statistics and the angular grid; whether each E57 image decodes");
  return RunCommand(app, argc, argv, [&] {
    CheckOutputFile("--json", json_path, {}, {path});
    const ScanSelector selector = SplitScanSelector(path);
    const std::string& file_path = selector.path;
    const std::string format = FileExtension(file_path);
    const bool headerless = format == "xyz" || format == "pts";
    ScanFileHeader header;
    if (!stats || !headerless) {
      header = ReadScanHeader(file_path);
      if (!stats) PrintWarnings(header.warnings);
    }
    if (!stats) {
      ScanFileSummary summary = SummarizeScanFile(header);
      KeepOnlyScan(selector, &summary);
      WriteJsonOutput(json_path, ToJson(summary), compact ? -1 : 2, /*inline_arrays=*/true);
      Summarize(BriefReport(summary));
      return 0;
    }
    ScanFile file;
    std::vector<E57Image> images;
    if (format == "e57") {  // read once, keeping the photos
      E57File e57 = ReadE57AndWarn(file_path);
      file = {file_path, "e57", std::move(e57.scans), std::move(e57.warnings)};
      images = std::move(e57.images);
    } else {
      file = ReadScanFileAndWarn(file_path);
    }
    if (headerless) {
      header.path = file_path;
      header.format = format;
      header.format_version = format == "pts" ? "PTS" : "XYZ";
      header.file_size_bytes = CheckRegularFile(file_path);
      for (const Scan& scan : file.scans) header.scans.push_back(ScanHeaderOf(scan));
    }
    ScanFileStatistics summary = SummarizeScanFileStatistics(header, file.scans, SummarizeE57Images(images));
    KeepOnlyScan(selector, &summary);
    WriteJsonOutput(json_path, ToJson(summary), compact ? -1 : 2, /*inline_arrays=*/true);
    Summarize(BriefReport(summary));
    return 0;
  });
}

int RunConvert(int argc, char** argv) {
  CLI::App app{
      fmt::format(
          "Convert a scan file between {}, keeping the grid where the target can hold it ({} hold points "
          "only, in the world frame). Prints one warning for each thing the target cannot hold (labels, "
          "normals, photos, second returns, ...) and one line of what it wrote (not with --quiet). "
          "`lidarshop "
          "formats` lists what each format holds.",
          FormatNamesWhere([](const ScanFormatInfo& f) { return f.write; }, "and"),
          FormatNamesWhere([](const ScanFormatInfo& f) { return f.write && !f.grid; }, "and")),
      "convert"};
  std::string input, output, json_path;
  int scan_index = -1;
  bool quiet = false, drop_synthesized = false;
  std::string synthesized_mask_path;
  E57WriteOptions e57_options;
  OptionBinder binder(app);
  app.add_option("input", input, "scan file to read")->required();
  app.add_option("output", output, "scan file to write (format from the extension)")->required();
  app.add_option("--scan", scan_index, "write only scan K (from 0); PCD holds one scan");
  app.add_flag("--drop-synthesized", drop_synthesized,
               "leave synthesized points out (for targets that cannot mark them: XYZ, PTS, PTX)");
  app.add_option(
      "--synthesized-mask", synthesized_mask_path,
      "PNG of the scan's grid (rows x cols, 1 x N for clouds): 255 = a synthesized point, so that "
      "targets that cannot mark them lose nothing (one scan: give --scan K for a file of several)");
  AddJsonOption(app, &json_path);
  // --e57-precision-m names the scaled-integer step; --coordinate-scale-m stays (an earlier contract).
  binder.Bind(&e57_options, {.flags = {{"coordinate_scale_m", "--coordinate-scale-m,--e57-precision-m"}},
                             .group = "E57 output"});
  AddQuietFlag(app, &quiet);
  LasWriteOptions las;
  binder.Bind(&las, {.flags = {{"minor_version", "--las-minor-version"},
                               {"point_format", "--las-point-format"},
                               {"coordinate_scale_m", "--las-scale"}},
                     .group = "LAS output"});
  return RunCommand(
      app, argc, argv,
      [&] {
        binder.Validate(e57_options);
        binder.Validate(las);
        CheckOutputPath(output, {input});
        CheckOutputFile("--json", json_path, {}, {input, output});
        CheckOutputFile("--synthesized-mask", synthesized_mask_path, {"png"}, {input, output, json_path});
        const auto progress = Progress::ForTerminal("convert", 2, quiet);
        ScanFile file;
        std::vector<E57Image> images;         // E57 -> E57 keeps the photos
        std::vector<Scan> second_returns;     // E57 input: one per scan, 0 x 0 = none
        if (FileExtension(input) == "e57") {  // photos and second returns, to keep or to report
          E57File e57 = ReadE57AndWarn(input);
          second_returns = std::move(e57.second_returns);
          file = {input, "e57", std::move(e57.scans), std::move(e57.warnings)};
          images = std::move(e57.images);
        } else {
          file = ReadScanFileAndWarn(input);
        }
        progress->Advance();
        std::vector<Scan> scans = file.scans;
        if (scan_index >= 0) {
          scans = {PickScan(file, scan_index, "--scan")};
          if (!second_returns.empty()) second_returns = {second_returns[scan_index]};
        }
        if (!synthesized_mask_path.empty()) {
          if (scans.size() != 1) {
            throw OptionsError(fmt::format("--synthesized-mask: {} holds {} scans; choose one with --scan K",
                                           input, scans.size()));
          }
          WriteSynthesizedMask(synthesized_mask_path, scans[0]);
        }
        int64_t dropped_synthesized = 0;
        if (drop_synthesized) {
          for (Scan& scan : scans) {
            if (scan.synthesized.empty()) continue;
            dropped_synthesized += cv::countNonZero(scan.synthesized & scan.valid);
            scan = MaskScan(scan, scan.synthesized == 0);
            scan.synthesized.release();
          }
        }
        const bool to_e57 = FileExtension(output) == "e57";
        size_t scans_with_second_returns = 0;
        for (const Scan& second : second_returns) scans_with_second_returns += second.CountValid() > 0;
        // E57 -> E57 keeps the second returns; every other target drops them (and says so).
        const ScanWritePlan plan =
            PlanScanWrite(output, scans, images.size(), to_e57 ? 0 : scans_with_second_returns, &las);
        if (to_e57) {
          E57File out;
          out.scans = scans;
          out.second_returns = second_returns;
          out.images = images;
          WriteE57(output, out, e57_options);
        } else if (FileExtension(output) == "las") {
          WriteLas(output, scans, las);
        } else {
          WriteScanFile(output, scans);
        }
        progress->Advance();
        progress->Finish();
        // After a successful write: what the target could not hold, one line each, then what it holds.
        PrintWarnings(plan.dropped);
        const size_t images_written = to_e57 ? images.size() : 0;
        Summarize(WrittenSummary(output, scans, images_written, plan));
        ScanWriteSummary summary = SummarizeScanWrite(input, output, scans, images_written, plan);
        if (drop_synthesized) summary.synthesized_left_out = dropped_synthesized;
        WriteJsonOutput(json_path, CommandJson(ToJson(e57_options), ToJson(summary)));
        return 0;
      },
      &binder);
}

// The object names of a scene file or a built-in scene, by label, for the labels legend.
std::map<int32_t, std::string> SceneLabelNames(const std::string& scene) {
  for (const BuiltinScene& builtin : BuiltinScenes()) {
    if (scene == builtin.name) {
      return ObjectNamesByLabel(ParseScene(builtin.json, fmt::format("built-in scene '{}'", scene), ""));
    }
  }
  return ObjectNamesByLabel(LoadScene(scene));
}

bool IsFloatPicture(const std::string& path) {
  const std::string extension = FileExtension(path);
  return extension == "exr" || extension == "tif" || extension == "tiff";
}

int RunRender(int argc, char** argv) {
  CLI::App app{
      "Render a channel of a scan as a picture, row 0 = top (highest elevation): square angular pixels by "
      "default (--aspect native: one pixel per ray); an unorganized cloud is projected onto a spherical grid "
      "around the scanner (--view top|front|side: orthographic, at least 1000 pixels on the longer side, "
      "each point a square sized from the local point spacing, coloured by elevation unless --channel says "
      "otherwise). .exr / .tif write the values as 32-bit floats. "
      "The picture's layout goes beside it (PICTURE.layout.json): strokes and masks painted on the picture "
      "map onto the scan's cells (segment, remove, fill). --eye, --orbit or --camera draw the points from "
      "another viewpoint, the scan's up kept up.",
      "render"};
  std::string input, output, channel, color_map, json_path, scene_names;
  int scan_index = 0, width_px = 0, height_px = 0;
  RenderOptions options;
  PictureLayoutOptions layout_options;
  OptionBinder binder(app);
  app.add_option("file", input, "scan file")->required();
  app.add_option(
         "-o,--output", output,
         "picture to write: .png, .jpg (colours); .exr, .tif (range or elevation in metres, intensity "
         "or normals as 32-bit floats, NaN where no return)")
      ->required();
  AddJsonOption(app, &json_path);
  // RenderOptions is not described (an optional colour map, NaN bounds): its flags are bound here, with the
  // choices of the described enums.
  const EnumInfo& channels = EnumInfoOf<RenderChannel>();
  const EnumInfo& color_maps = EnumInfoOf<ColorMap>();
  app.add_option("--channel", channel,
                 "what to draw (default: range; elevation in the top, front and side views)")
      ->check(ChoiceOf(channels));
  app.add_flag("--legend", options.legend,
               "add a colour scale bar, label or class swatches with names, or the normals key to the right");
  app.add_option("--scan", scan_index, "which scan of the file (from 0)")->capture_default_str();
  app.add_option("--colormap", color_map,
                 "colour map of metric channels (default: viridis for range and elevation, gray "
                 "for intensity)")
      ->check(ChoiceOf(color_maps, {"grey"}));
  app.add_option(
      "--min", options.min_value,
      "value of the first colour (metres for range and elevation, the file's units for intensity); "
      "default: 1 % quantile");
  app.add_option("--max", options.max_value, "value of the last colour; default: 99 % quantile");
  app.add_flag("--hillshade", options.hillshade,
               "top, front and side views: shade the colours by the slope of the surface (lit from the "
               "north-west)");
  app.add_option("--scene", scene_names,
                 "a scene file or built-in scene whose object names label the labels legend");
  // Picture size: the ray picture's and the second viewpoint's.
  app.add_option("--width", width_px,
                 "picture width in pixels (default: automatic; second viewpoint: 640); with only --width or "
                 "--height the other keeps the aspect")
      ->check(CLI::Range(16, 16384));
  app.add_option("--height", height_px,
                 "picture height in pixels (default: automatic; second viewpoint: 480)")
      ->check(CLI::Range(16, 16384));
  // A second viewpoint: the points seen by a pinhole camera (colours, or grey intensity).
  std::vector<double> eye, target;
  double orbit_deg = std::numeric_limits<double>::quiet_NaN();
  std::string around_path;
  PointViewOptions view;
  app.add_option("--eye", eye, "camera centre x,y,z in the world (metres): draw the points from there")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--target", target, "point x,y,z the camera looks at (with --eye)")
      ->delimiter(',')
      ->expected(3);
  std::vector<double> up;
  app.add_option("--up", up, "with --eye: the picture's up x,y,z in the world (default: the scan's up)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--orbit", orbit_deg,
                 "camera turned this many degrees about the scan's up, around the scan's (or --around's) "
                 "centre, from the scanner");
  app.add_option("--around", around_path,
                 "with --orbit: a mask PNG of the cells to look at (e.g. a filled hole; the grid's size or "
                 "painted on a render picture): the camera depends on the mask and the scan's pose only");
  std::string camera_path, write_camera_path;
  app.add_option("--camera", camera_path,
                 "draw the points with this camera file (JSON: eye, target, up, fov_deg, width, height; "
                 "metres, degrees), e.g. one --write-camera wrote");
  app.add_option("--write-camera", write_camera_path, "write the camera of --eye, --orbit or --camera here");
  binder.Bind(&view, {.keys = {"field_of_view_deg", "synthesized_tint"},
                      .flags = {{"field_of_view_deg", "--fov"}, {"synthesized_tint", "--tint-synthesized"}},
                      .group = "Second viewpoint (--eye / --orbit)"});
  binder.NameFlag("width_px", "--width");
  binder.NameFlag("height_px", "--height");
  // --point-size sets the squares of the orthographic views and of the second viewpoint alike.
  binder.Bind(&layout_options, {.keys = {"view", "aspect", "point_size_px"},
                                .flags = {{"point_size_px", "--point-size"}},
                                .group = "Picture layout"});
  bool quiet = false;
  AddQuietFlag(app, &quiet);
  return RunCommand(
      app, argc, argv,
      [&] {
        if (width_px > 0) view.width_px = layout_options.width_px = width_px;
        if (height_px > 0) view.height_px = layout_options.height_px = height_px;
        if (layout_options.point_size_px > 0) view.point_size_px = layout_options.point_size_px;
        binder.Validate(view);
        binder.Validate(layout_options);
        CheckOutputPath(output, {input, around_path, camera_path});
        CheckOutputFile("--json", json_path, {}, {input, around_path, camera_path, output});
        CheckOutputFile("--write-camera", write_camera_path, {"json"},
                        {input, around_path, camera_path, output, json_path});
        const int viewpoints = !eye.empty() + !std::isnan(orbit_deg) + !camera_path.empty();
        if (viewpoints > 1) throw OptionsError("give one of --eye, --orbit and --camera");
        if (viewpoints == 0 && !write_camera_path.empty()) {
          throw OptionsError("--write-camera writes the camera of --eye, --orbit or --camera");
        }
        if (!up.empty() && eye.empty())
          throw OptionsError("--up goes with --eye (a camera file holds its up)");
        // The picture's layout file goes beside it (picture_mapping.h); checked before the long work.
        if (viewpoints == 0) {
          CheckOutputFile("-o", LayoutFilePath(output), {}, {input, around_path, camera_path, json_path});
        }
        if (viewpoints == 1) {
          if (!eye.empty() && target.size() != 3) throw OptionsError("--eye needs --target x,y,z");
          const ScanFile file = ReadScanFileAndWarn(input);
          const Scan& scan = PickScan(file, scan_index, "--scan");
          PointViewResult result;
          if (!eye.empty()) {
            view.eye_in_world = Eigen::Vector3d(eye[0], eye[1], eye[2]);
            view.target_in_world = Eigen::Vector3d(target[0], target[1], target[2]);
            if (!up.empty()) view.up_in_world = Eigen::Vector3d(up[0], up[1], up[2]);
          } else if (!camera_path.empty()) {
            constexpr int64_t kMaxCameraBytes = int64_t{1} << 20;
            ParseCameraJson(ReadRegularFile(camera_path, kMaxCameraBytes), camera_path, &view);
          } else {
            const cv::Mat region = around_path.empty() ? cv::Mat(scan.valid != 0)
                                                       : ReadMaskForScan(around_path, scan, "", input);
            // Up: the ground's normal when the scan shows a ground (found outside the mask, so that views
            // before and after an edit inside it keep one camera), else the scan's own up.
            const std::optional<GroundPlane> ground =
                FindGround(scan, around_path.empty() ? cv::Mat() : region);
            const PointViewOptions side =
                SideView(scan, region, orbit_deg, ground ? ground->normal_in_world : Eigen::Vector3d::Zero());
            result.up_from = ground ? "ground" : "scan";
            if (ground) {
              result.ground = ViewGround{ground->share, ground->tilt_deg};
              if (!quiet) {
                fmt::print(
                    stderr,
                    "lidarshop render: up is the ground's normal ({:.0f} % of the returns on one plane, "
                    "{:.1f}° from the scanner's z)\n",
                    100 * ground->share, ground->tilt_deg);
              }
            }
            view.eye_in_world = side.eye_in_world;
            view.target_in_world = side.target_in_world;
            view.up_in_world = side.up_in_world;
          }
          const cv::Mat picture = RenderPointView(scan, view);
          WriteImage(output, picture);
          result.camera = CameraOf(view, scan);
          if (!write_camera_path.empty()) WriteJsonOutput(write_camera_path, ToJson(result.camera), 2, true);
          result.output = output;
          result.width_px = picture.cols;
          result.height_px = picture.rows;
          result.eye_in_world = result.camera.eye;
          result.target_in_world = result.camera.target;
          result.up_in_world = result.camera.up;
          if (!quiet) {
            auto xyz = [](const Eigen::Vector3d& v) {
              return fmt::format("{:.3f}, {:.3f}, {:.3f}", v.x(), v.y(), v.z());
            };
            fmt::print(stderr,
                       "lidarshop render: the points seen from ({}) looking at ({}), up ({}): {} x {}\n",
                       xyz(view.eye_in_world), xyz(view.target_in_world),
                       xyz(view.up_in_world.isZero(0) ? ScanUpInWorld(scan) : view.up_in_world), picture.cols,
                       picture.rows);
          }
          WriteJsonOutput(json_path, CommandJson(ToJson(view), ToJson(result)));
          Summarize(fmt::format("{} x {} view from ({:.2f}, {:.2f}, {:.2f}) -> {}", picture.cols,
                                picture.rows, view.eye_in_world.x(), view.eye_in_world.y(),
                                view.eye_in_world.z(), output));
          return 0;
        }
        const bool orthographic = TowardViewer(layout_options.view) != Eigen::Vector3d::Zero();
        if (channel.empty()) channel = orthographic ? "elevation" : "range";
        options.channel = ParseEnum<RenderChannel>(channel);
        if (!color_map.empty())
          options.color_map = (color_map == "grey" ? ColorMap::kGray : ParseEnum<ColorMap>(color_map));
        options.Check();
        const bool float_picture = IsFloatPicture(output);
        if (float_picture && options.legend) {
          throw OptionsError(fmt::format("--legend draws on 8-bit pictures; {} holds float values", output));
        }
        if (float_picture && (!HasFloatValues(options.channel) || options.hillshade)) {
          throw OptionsError(
              fmt::format("{}: float pictures hold range, elevation, intensity or normals, not {}{}; "
                          "write a .png",
                          output, channel, options.hillshade ? " with --hillshade" : ""));
        }
        if (options.hillshade && !orthographic) {
          throw OptionsError("--hillshade shades the orthographic views: give --view top, front or side");
        }
        if (!scene_names.empty()) options.label_names = SceneLabelNames(scene_names);
        const ScanFile file = ReadScanFileAndWarn(input);
        Scan scan = PickScan(file, scan_index, "--scan");
        // Errors about the scan's channels name the file (and the scan, when the file names it).
        scan.name = scan.name.empty() ? input : fmt::format("{} (scan '{}')", input, scan.name);
        PictureSummary summary{.output = output, .channel = channel};
        PictureLayout layout;
        cv::Size image_size;
        if (float_picture) {
          ValuesResult values = RenderValues(scan, options.channel, layout_options);
          WriteImage(output, values.values);
          image_size = values.values.size();
          summary.values =
              options.channel == RenderChannel::kRange || options.channel == RenderChannel::kElevation
                  ? "float32 metres, NaN = no return"
                  : "float32, NaN = no return";
          layout = std::move(values.layout);
        } else {
          PictureResult result = RenderPicture(scan, options, layout_options);
          WriteImage(output, result.image);
          image_size = result.image.size();
          if (result.scale) {
            summary.scale = ColorScaleSummary{
                .min = result.scale->min_value, .max = result.scale->max_value, .unit = result.scale->unit};
          }
          summary.legend = std::move(result.legend_lines);
          layout = std::move(result.layout);
        }
        summary.width_px = image_size.width;
        summary.height_px = image_size.height;
        summary.layout = SummarizeLayout(layout);
        // The layout beside the picture: what strokes and masks painted on it map onto (picture_mapping.h).
        summary.layout_file = LayoutFilePath(output);
        WriteJsonOutput(summary.layout_file, LayoutFileJson(layout, scan, image_size));
        Summarize(layout.Describe());
        WriteJsonOutput(json_path, CommandJson(ToJson(view), ToJson(summary)));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
