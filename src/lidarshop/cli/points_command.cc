// lidarshop points: the point-set toolbox over scans and clouds (pointset/*.h, docs/points.md).
//
//   lidarshop points OPERATION IN... -o OUT [options] [--json FILE|-]
//
// (`register` is in register_command.cc.)
//
// Every input scan is taken in the world frame and the operation sees all of them as one cloud. Operations
// that drop points (outliers, crop, sample) or label them (planes, cluster, kmeans) or give normals keep
// every scan's grid: dropped cells become cells without a return, labels and normals go into the scans'
// channels. Operations that make new points (voxel, merge) write a plain cloud (.ply / .pcd) in the world
// frame.
#include <cmath>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/cli/points_operations.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/pointset/surface.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

template <>
const StructInfo& InfoOf<cli::PointsOptions>() {
  static const StructInfo info = [] {
    using cli::PointsOptions;
    StructBuilder<PointsOptions> b("PointsOptions", "the options of the points operations");
    b.Field(&PointsOptions::statistical, "statistical", "outliers --method statistical");
    b.Field(&PointsOptions::radius, "radius", "outliers --method radius");
    b.Field(&PointsOptions::crop, "crop", "crop (box and polygon: --box, --polygon)");
    b.Field(&PointsOptions::normals, "normals", "normals, and regions' grid normals");
    b.Field(&PointsOptions::planes, "planes", "planes (RANSAC)");
    b.Field(&PointsOptions::hough, "hough", "planes --hough");
    b.Field(&PointsOptions::cluster, "cluster", "cluster");
    b.Field(&PointsOptions::kmeans, "kmeans", "kmeans");
    b.Field(&PointsOptions::mesh, "mesh", "mesh (--method grid)");
    b.Field(&PointsOptions::surface, "surface", "mesh --method poisson | scale-space");
    b.Field(&PointsOptions::regions, "regions", "regions");
    b.Field(&PointsOptions::superpixels, "superpixels", "superpixels");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop

namespace lidarshop::cli {
namespace {

// The options of the members `operation` uses (mesh: the grid mesh's or the surface's, by its method).
nlohmann::ordered_json UsedOptions(const PointsOptions& options, const PointsOperation& operation,
                                   const PointsFlags& flags) {
  const nlohmann::ordered_json all = ToJson(options);
  nlohmann::ordered_json used = nlohmann::ordered_json::object();
  for (const std::string& key : operation.options) {
    if (operation.name == "mesh" &&
        key != ((flags.method.empty() || flags.method == "grid") ? "mesh" : "surface"))
      continue;
    used[key] = all[key];
  }
  return used;
}

// "1,2.5,-3" as numbers; "" as none.
std::vector<double> ParseNumbers(const std::string& text, const std::string& flag) {
  std::vector<double> numbers;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      size_t used = 0;
      numbers.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw OptionsError(fmt::format("{}: '{}' is not a number", flag, item));
    }
  }
  return numbers;
}

void CheckOutputs(const std::string& output, const std::string& json,
                  const std::vector<std::string>& inputs) {
  CheckScanFileFormat(output);
  CheckOutputPath(output, inputs);
  if (!json.empty() && json != "-") {
    std::vector<std::string> others = inputs;
    others.push_back(output);
    CheckOutputPath(json, others);
  }
}

}  // namespace

int RunPoints(int argc, char** argv) {
  CLI::App app{
      "Point-set tools over scans and clouds (docs/points.md). OPERATION: " + PointsOperationNames(" | ") +
          " (sample-mesh: IN = a triangle mesh). Scans keep their grid where the operation allows.",
      "points"};
  std::string operation, output_path, json_path;
  std::vector<std::string> inputs;
  std::string box_text, polygon_text;
  PointsFlags flags;
  PointsOptions points;
  // Flags shared by several operations set the first struct's field and are copied to the others when
  // given; the others start from the same value, so a flag left out changes nothing.
  points.mesh.world_frame = true;
  points.normals.neighbors = points.statistical.neighbors;
  points.cluster.radius_m = points.radius.radius_m;
  points.surface.normal_neighbors = points.statistical.neighbors;
  OptionBinder binder(app);
  app.add_option("operation", operation, "the tool")->required();
  app.add_option("inputs", inputs, "scan or cloud files (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts)")
      ->required();
  app.add_option("-o,--output", output_path, "output file; a scan format keeps the grid")->required();
  AddJsonOption(app, &json_path);
  app.add_option("--method", flags.method,
                 "outliers: statistical (default) | radius; mesh: grid (default: the scans' grid mesh) | "
                 "poisson | scale-space (surface reconstruction)");
  app.add_option("--voxel", flags.voxel_m, "voxel: cube side, metres")->capture_default_str();
  app.add_option("--count", flags.count, "sample: points to keep; sample-mesh: points to draw")
      ->capture_default_str();
  app.add_option("--box", box_text, "crop: xmin,ymin,zmin,xmax,ymax,zmax (world, metres)");
  app.add_option("--polygon", polygon_text, "crop: x1,y1,x2,y2,... (world xy, metres)");
  app.add_option("--matrix", flags.matrix_text,
                 "transform: new_world_from_world as 16 comma-separated numbers (row major), "
                 "x,y,z,yaw_deg[,pitch_deg,roll_deg] or a pose file (as verify --pose)");
  app.add_flag("--grid", flags.grid_normals, "normals: from the scan grid instead of a KD-tree");
  app.add_flag("--hough", flags.hough, "planes: Hough detection (ball accumulator) instead of RANSAC");
  app.add_option("--max-angle", flags.max_angle_deg,
                 "regions: largest normal angle between neighbours, degrees")
      ->capture_default_str();
  binder.Bind(&points, {.keys = {"statistical.neighbors", "statistical.std_ratio", "radius.radius_m",
                                 "radius.min_neighbors", "planes.seed"},
                        .flags = {{"statistical.neighbors", "--neighbors"},
                                  {"statistical.std_ratio", "--std-ratio"},
                                  {"radius.radius_m", "--radius"},
                                  {"radius.min_neighbors", "--min-neighbors"},
                                  {"planes.seed", "--seed"}},
                        .group = "outliers (--neighbors, --radius also normals and cluster; --seed every "
                                 "random choice)"});
  binder.Bind(&points, {.keys = {"crop.labels", "crop.min_range_m", "crop.max_range_m", "crop.min_intensity",
                                 "crop.max_intensity", "crop.invert"},
                        .flags = {{"crop.labels", "--labels"},
                                  {"crop.min_range_m", "--min-range"},
                                  {"crop.max_range_m", "--max-range"},
                                  {"crop.min_intensity", "--min-intensity"},
                                  {"crop.max_intensity", "--max-intensity"},
                                  {"crop.invert", "--invert"}},
                        .group = "crop"});
  binder.Bind(&points, {.keys = {"normals.window_cells", "normals.max_neighbors"},
                        .flags = {{"normals.window_cells", "--window"}},
                        .group = "normals"});
  binder.Bind(&points, {.keys = {"planes.distance_threshold_m", "planes.max_iterations", "planes.confidence",
                                 "planes.min_inliers", "planes.max_planes", "hough.angle_step_deg",
                                 "hough.max_voters"},
                        .flags = {{"planes.distance_threshold_m", "--distance"},
                                  {"planes.max_iterations", "--iterations"},
                                  {"planes.min_inliers", "--min-inliers"},
                                  {"planes.max_planes", "--planes"},
                                  {"hough.angle_step_deg", "--angle-step"}},
                        .group = "planes"});
  binder.Bind(&points, {.keys = {"cluster.min_points", "cluster.max_points", "kmeans.clusters",
                                 "kmeans.max_iterations", "kmeans.tolerance_m"},
                        .flags = {{"cluster.min_points", "--min-points"}, {"kmeans.clusters", "--k"}},
                        .group = "cluster, kmeans"});
  binder.Bind(&points, {.keys = {"mesh.max_range_jump_ratio", "mesh.max_edge_m", "mesh.world_frame",
                                 "regions.min_region_cells", "regions.max_range_jump_ratio"},
                        .flags = {{"mesh.max_range_jump_ratio", "--mesh-jump"},
                                  {"mesh.max_edge_m", "--max-edge"},
                                  {"regions.min_region_cells", "--min-cells"}},
                        .group = "mesh, regions (--max-edge also mesh --method scale-space)"});
  binder.Bind(&points,
              {.keys = {"surface.poisson_angle_deg", "surface.poisson_radius_spacings",
                        "surface.poisson_distance_spacings", "surface.keep_within_m",
                        "surface.scale_space_iterations", "surface.scale_space_neighbors"},
               .flags = {{"surface.poisson_angle_deg", "--poisson-angle"},
                         {"surface.poisson_radius_spacings", "--poisson-radius"},
                         {"surface.poisson_distance_spacings", "--poisson-distance"},
                         {"surface.keep_within_m", "--keep-within"},
                         {"surface.scale_space_iterations", "--smoothing-steps"},
                         {"surface.scale_space_neighbors", "--smoothing-neighbors"}},
               .group = "mesh --method poisson | scale-space (--neighbors: k of estimated normals)"});
  binder.Bind(&points, {.keys = {"superpixels.method", "superpixels.region_cells", "superpixels.ruler",
                                 "superpixels.iterations", "superpixels.graph_sigma", "superpixels.graph_k",
                                 "superpixels.graph_min_cells", "superpixels.range_weight",
                                 "superpixels.quickshift_kernel_size", "superpixels.quickshift_max_dist",
                                 "superpixels.quickshift_ratio"},
                        .flags = {{"superpixels.method", "--superpixel-method"},
                                  {"superpixels.region_cells", "--region-cells"}},
                        .group = "superpixels"});
  binder.NameFlag("normals.neighbors", "--neighbors");
  binder.NameFlag("normals.radius_m", "--radius");
  binder.NameFlag("cluster.radius_m", "--radius");
  binder.NameFlag("surface.normal_neighbors", "--neighbors");
  binder.NameFlag("surface.max_edge_m", "--max-edge");
  for (const char* key : {"hough.seed", "kmeans.seed", "surface.seed"}) binder.NameFlag(key, "--seed");
  return RunCommand(
      app, argc, argv,
      [&]() {
        if (app.count("--neighbors") > 0)
          points.normals.neighbors = points.surface.normal_neighbors = points.statistical.neighbors;
        if (app.count("--max-edge") > 0) points.surface.max_edge_m = points.mesh.max_edge_m;
        if (app.count("--radius") > 0)
          points.normals.radius_m = points.cluster.radius_m = points.radius.radius_m;
        if (app.count("--seed") > 0)
          points.hough.seed = points.kmeans.seed = points.surface.seed = points.planes.seed;
        const PointsOperation& op = FindPointsOperation(operation);
        if (op.name == "mesh" && !flags.method.empty() && flags.method != "grid") {
          if (flags.method != "poisson" && flags.method != "scale-space")
            throw OptionsError(
                fmt::format("--method '{}': mesh takes grid, poisson or scale-space", flags.method));
          points.surface.method = ParseEnum<SurfaceMethod>(flags.method);
        }
        binder.Validate(points);
        CheckOutputs(output_path, json_path, inputs);
        if (op.writes != PointsOutputKind::kScans && FileExtension(output_path) != "ply") {
          throw OptionsError(
              fmt::format("-o {}: {} writes a {}, as .ply", output_path, op.name,
                          op.writes == PointsOutputKind::kMesh ? "triangle mesh" : "plain cloud"));
        }
        flags.box = ParseNumbers(box_text, "--box");
        flags.polygon = ParseNumbers(polygon_text, "--polygon");
        if (!flags.box.empty() && flags.box.size() != 6)
          throw OptionsError("--box needs 6 numbers: xmin,ymin,zmin,xmax,ymax,zmax");
        PointsRead read{.operation = op.name};
        Gathered g;
        TriangleMesh mesh_in;
        if (op.reads_mesh) {
          if (inputs.size() != 1) throw OptionsError(fmt::format("{} takes one mesh (.ply, .obj)", op.name));
          CheckOption(flags.count > 0, fmt::format("--count must be > 0, got {}", flags.count));
          // Before reading the mesh: the samples, and the written cloud's copy of them.
          CheckMemoryBudget(SaturatingBytes(flags.count, 2 * kSurfaceSampleBytes),
                            fmt::format("--count {}: sampling {} points", flags.count, flags.count));
          mesh_in = ReadMeshAndWarn(inputs[0]);
          if (mesh_in.empty()) throw InputError(fmt::format("{}: the mesh has no triangles", inputs[0]));
        } else {
          const Timer read_timer;
          g = GatherScans(inputs);
          read.input_points = static_cast<int64_t>(g.cloud.size());
          read.scans = g.scans.size();
          read.read_seconds = read_timer.Seconds();
        }
        const Timer timer;  // the operation alone, without reading and writing
        const PointsOutput out = op.run(g, mesh_in, points, flags, read, timer);
        switch (op.writes) {
          case PointsOutputKind::kScans:
            WriteScanFile(output_path, out.scans);
            break;
          case PointsOutputKind::kCloud:
            WritePointCloud(output_path, out.cloud);
            break;
          case PointsOutputKind::kMesh:
            WriteMesh(output_path, out.mesh);
            break;
        }
        WriteJsonOutput(json_path, CommandJson(UsedOptions(points, op, flags), out.report));
        Summarize(out.summary_line + " -> " + output_path);
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
