// lidarshop info | convert | render: describe, convert and picture scan files.
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/render.h"
#include "lidarshop/io/render_view.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"

namespace lidarshop::cli {
namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;

nlohmann::json MatrixJson(const Eigen::Matrix4d& matrix) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  return rows;
}

nlohmann::json ScanJson(const Scan& scan, int index) {
  nlohmann::json json;
  json["index"] = index;
  if (!scan.name.empty()) json["name"] = scan.name;
  json["rows"] = scan.rows;
  json["cols"] = scan.cols;
  json["cells"] = scan.num_cells();
  json["valid"] = scan.CountValid();
  json["world_from_scanner"] = MatrixJson(scan.world_from_scanner);
  json["channels"] = ChannelNames(scan);

  // Bounds of the returns in the world frame, and range / intensity statistics.
  Eigen::AlignedBox3d world_bounds;
  double min_range = std::numeric_limits<double>::infinity(), max_range = 0, sum_range = 0;
  double min_intensity = std::numeric_limits<double>::infinity(), max_intensity = -min_intensity;
  int64_t count = 0;
  const Eigen::Matrix3d rotation = scan.world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = scan.world_from_scanner.topRightCorner<3, 1>();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
      world_bounds.extend(rotation * Eigen::Vector3d(p[0], p[1], p[2]) + translation);
      const double range = scan.range.at<float>(row, col);
      min_range = std::min(min_range, range);
      max_range = std::max(max_range, range);
      sum_range += range;
      const double intensity = scan.intensity.at<float>(row, col);
      min_intensity = std::min(min_intensity, intensity);
      max_intensity = std::max(max_intensity, intensity);
      ++count;
    }
  }
  if (count > 0) {
    json["bounds"] = {{"frame", "world"},
                      {"min", {world_bounds.min().x(), world_bounds.min().y(), world_bounds.min().z()}},
                      {"max", {world_bounds.max().x(), world_bounds.max().y(), world_bounds.max().z()}}};
    json["range_m"] = {{"min", min_range}, {"max", max_range}, {"mean", sum_range / count}};
    json["intensity"] = {{"min", min_intensity}, {"max", max_intensity}};
  } else {
    json["bounds"] = nullptr;
  }

  nlohmann::json grid;
  grid["fitted"] = scan.grid.fitted;
  grid["known"] = !scan.grid.azimuth_rad.empty();
  if (!scan.grid.azimuth_rad.empty() && !scan.grid.elevation_rad.empty()) {
    const auto [az_min, az_max] =
        std::minmax_element(scan.grid.azimuth_rad.begin(), scan.grid.azimuth_rad.end());
    const auto [el_min, el_max] =
        std::minmax_element(scan.grid.elevation_rad.begin(), scan.grid.elevation_rad.end());
    grid["azimuth_deg"] = {*az_min * kDegreesPerRadian, *az_max * kDegreesPerRadian};
    grid["elevation_deg"] = {*el_min * kDegreesPerRadian, *el_max * kDegreesPerRadian};
    if (scan.cols > 1) {
      grid["azimuth_step_deg"] = (*az_max - *az_min) / (scan.cols - 1) * kDegreesPerRadian;
    }
    if (scan.rows > 1) {
      grid["elevation_step_deg"] = (*el_max - *el_min) / (scan.rows - 1) * kDegreesPerRadian;
    }
  }
  grid["rms_residual_rad"] = scan.grid.rms_residual_rad;
  grid["max_residual_rad"] = scan.grid.max_residual_rad;
  grid["rms_residual_deg"] = scan.grid.rms_residual_rad * kDegreesPerRadian;
  json["grid"] = grid;
  json["grid_fit_rms_residual_rad"] = scan.grid.rms_residual_rad;
  return json;
}

}  // namespace

int RunInfo(int argc, char** argv) {
  CLI::App app{
      "Describe a scan file (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts) as one JSON object on stdout.",
      "info"};
  std::string path;
  bool compact = false;
  app.add_option("file", path, "scan file")->required();
  app.add_flag("--compact", compact, "print the JSON on one line");
  return RunCommand(app, argc, argv, [&] {
    ScanFile file;
    std::vector<E57Image> images;
    if (FileExtension(path) == "e57") {  // read once, keeping the photos
      E57File e57 = ReadE57(path);
      file = {path, "e57", std::move(e57.scans)};
      images = std::move(e57.images);
    } else {
      file = ReadScanFile(path);
    }
    nlohmann::json json;
    json["file"] = path;
    json["format"] = file.format;
    json["scans"] = nlohmann::json::array();
    for (size_t i = 0; i < file.scans.size(); ++i)
      json["scans"].push_back(ScanJson(file.scans[i], static_cast<int>(i)));
    if (file.format == "e57") json["images"] = ImagesJson(images);
    fmt::print("{}\n", json.dump(compact ? -1 : 2));
    return 0;
  });
}

int RunConvert(int argc, char** argv) {
  CLI::App app{
      "Convert a scan file between .ptx, .e57, .ply, .pcd, .las, .xyz and .pts, keeping the grid where the "
      "target can hold it (LAS, XYZ and PTS hold points only, in the world frame).",
      "convert"};
  std::string input, output;
  int scan_index = -1;
  bool quiet = false;
  app.add_option("input", input, "scan file to read")->required();
  app.add_option("output", output, "scan file to write (format from the extension)")->required();
  app.add_option("--scan", scan_index, "write only scan K (from 0); PCD holds one scan");
  AddQuietFlag(app, &quiet);
  LasWriteOptions las;
  OptionBinder binder(app);
  binder.Bind(&las, {.flags = {{"minor_version", "--las-minor-version"},
                               {"point_format", "--las-point-format"},
                               {"coordinate_scale_m", "--las-scale"}},
                     .group = "LAS output"});
  return RunCommand(
      app, argc, argv,
      [&] {
        CheckOutputPath(output, {input});
        binder.Validate(las);
        const auto progress = Progress::ForTerminal("convert", 2, quiet);
        ScanFile file;
        std::vector<E57Image> images;  // E57 -> E57 keeps the photos
        const bool e57_to_e57 = FileExtension(input) == "e57" && FileExtension(output) == "e57";
        if (e57_to_e57) {
          E57File e57 = ReadE57(input);
          file = {input, "e57", std::move(e57.scans)};
          images = std::move(e57.images);
        } else {
          file = ReadScanFile(input);
        }
        progress->Advance();
        std::vector<Scan> scans = file.scans;
        if (scan_index >= 0) scans = {PickScan(file, scan_index, "--scan")};
        if (e57_to_e57) {
          WriteE57(output, scans, images, E57WriteOptions{});
        } else if (FileExtension(output) == "las") {
          WriteLas(output, scans, las);
        } else {
          WriteScanFile(output, scans);
        }
        progress->Advance();
        progress->Finish();
        return 0;
      },
      &binder);
}

int RunRender(int argc, char** argv) {
  CLI::App app{"Render a channel of a scan as a picture: one pixel per ray, row 0 = top (highest elevation).",
               "render"};
  std::string input, output, channel = "range", color_map;
  int scan_index = 0;
  RenderOptions options;
  app.add_option("file", input, "scan file")->required();
  app.add_option("-o,--output", output, "picture to write (.png, .jpg)")->required();
  app.add_option("--channel", channel, "range | rgb | intensity | normals | labels | valid")
      ->capture_default_str()
      ->check(CLI::IsMember({"range", "rgb", "intensity", "normals", "labels", "valid"}));
  app.add_flag("--legend", options.legend, "add a colour scale bar (or label swatches) to the right");
  app.add_option("--scan", scan_index, "which scan of the file (from 0)")->capture_default_str();
  app.add_option("--colormap", color_map, "viridis | turbo | magma | gray (metric channels)")
      ->check(CLI::IsMember({"viridis", "turbo", "magma", "gray"}));
  app.add_option("--min", options.min_value,
                 "value of the first colour (metres for range); default: 1 % quantile");
  app.add_option("--max", options.max_value, "value of the last colour; default: 99 % quantile");
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
  app.add_option("--orbit", orbit_deg,
                 "camera turned this many degrees around the scan's (or --around's) centre from the scanner");
  app.add_option("--around", around_path,
                 "with --orbit: a mask PNG of the cells to look at (e.g. a filled hole)");
  app.add_option("--fov", view.field_of_view_deg, "horizontal field of view of --eye/--orbit, degrees")
      ->capture_default_str();
  app.add_option("--width", view.width_px, "picture width of --eye/--orbit, pixels")->capture_default_str();
  app.add_option("--height", view.height_px, "picture height of --eye/--orbit, pixels")
      ->capture_default_str();
  app.add_option("--point-size", view.point_size_px, "drawn point size of --eye/--orbit, pixels")
      ->capture_default_str();
  app.add_option("--tint-synthesized", view.synthesized_tint,
                 "with --eye/--orbit: tint synthesized points magenta by this share (0..1)")
      ->capture_default_str();
  bool quiet = false;  // rendering shows no progress; accepted like every other command's --quiet
  AddQuietFlag(app, &quiet);
  return RunCommand(app, argc, argv, [&] {
    CheckOutputPath(output, {input, around_path});
    if (!eye.empty() || !std::isnan(orbit_deg)) {
      if (!eye.empty() && !std::isnan(orbit_deg)) throw OptionsError("give --eye or --orbit, not both");
      if (!eye.empty() && target.size() != 3) throw OptionsError("--eye needs --target x,y,z");
      const ScanFile file = ReadScanFile(input);
      const Scan& scan = PickScan(file, scan_index, "--scan");
      if (!eye.empty()) {
        view.eye_in_world = Eigen::Vector3d(eye[0], eye[1], eye[2]);
        view.target_in_world = Eigen::Vector3d(target[0], target[1], target[2]);
      } else {
        const cv::Mat region = around_path.empty()
                                   ? cv::Mat(scan.valid != 0)
                                   : ReadMask(around_path, cv::Size(scan.cols, scan.rows), input);
        const PointViewOptions side = SideView(scan, region, orbit_deg);
        view.eye_in_world = side.eye_in_world;
        view.target_in_world = side.target_in_world;
      }
      WriteImage(output, RenderPointView(scan, view));
      return 0;
    }
    options.channel = ParseEnum<RenderChannel>(channel);
    if (!color_map.empty())
      options.color_map = (color_map == "grey" ? ColorMap::kGray : ParseEnum<ColorMap>(color_map));
    options.Check();
    const ScanFile file = ReadScanFile(input);
    Scan scan = PickScan(file, scan_index, "--scan");
    if (scan.name.empty()) scan.name = input;
    const RenderResult result = RenderScan(scan, options);
    WriteImage(output, result.image);
    return 0;
  });
}

}  // namespace lidarshop::cli
