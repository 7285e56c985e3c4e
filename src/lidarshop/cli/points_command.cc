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
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/pointset/surface.h"
#include "lidarshop/scanner/scan_mesh.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"
#include "lidarshop/verify/pose_text.h"

namespace lidarshop::cli {

// The options of every points operation, one member per library struct: `--options FILE` sets them by
// operation ({"planes": {"max_planes": 3}}), and --json's "options" holds the ones the operation used.
struct PointsOptions {
  StatisticalOutlierOptions statistical;
  RadiusOutlierOptions radius;
  CropOptions crop;
  NormalOptions normals;
  RansacPlaneOptions planes;
  HoughPlaneOptions hough;
  EuclideanClusterOptions cluster;
  KMeansOptions kmeans;
  ScanMeshOptions mesh;
  SurfaceOptions surface;
  RegionGrowingOptions regions;
  SuperpixelOptions superpixels;
};

}  // namespace lidarshop::cli

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

// The members of PointsOptions each operation uses.
const std::map<std::string, std::vector<std::string>>& OptionsOfOperation() {
  static const std::map<std::string, std::vector<std::string>> used = {
      {"outliers", {"statistical", "radius"}},
      {"crop", {"crop"}},
      {"normals", {"normals"}},
      {"planes", {"planes", "hough"}},
      {"cluster", {"cluster"}},
      {"kmeans", {"kmeans"}},
      {"mesh", {"mesh", "surface"}},
      {"regions", {"regions", "normals"}},
      {"superpixels", {"superpixels"}}};
  return used;
}

// `mesh_method`: "grid" uses "mesh", a surface reconstruction "surface".
nlohmann::ordered_json UsedOptions(const PointsOptions& options, const std::string& operation,
                                   const std::string& mesh_method = "grid") {
  const nlohmann::ordered_json all = ToJson(options);
  nlohmann::ordered_json used = nlohmann::ordered_json::object();
  if (operation == "mesh") {
    const std::string key = mesh_method == "grid" ? "mesh" : "surface";
    used[key] = all[key];
    return used;
  }
  const auto found = OptionsOfOperation().find(operation);
  if (found == OptionsOfOperation().end()) return used;
  for (const std::string& key : found->second) used[key] = all[key];
  return used;
}

// The summary line of a points operation, from its --json summary: what it kept or found, of how many points.
std::string PointsSummary(const nlohmann::ordered_json& summary, const std::string& output_path) {
  const std::string operation = summary["operation"].get<std::string>();
  std::string what = fmt::format("{}: {} input points", operation, summary["input_points"].get<int64_t>());
  if (summary.contains("output_points"))
    what += fmt::format(", {} output points", summary["output_points"].get<int64_t>());
  for (const char* key : {"clusters", "regions", "superpixels"}) {
    if (summary.contains(key)) what += fmt::format(", {} {}", summary[key].get<int64_t>(), key);
  }
  if (summary.contains("planes")) what += fmt::format(", {} planes", summary["planes"].size());
  return what + " -> " + output_path;
}

// All scans of all inputs as one world-frame cloud, with where each point came from.
struct Gathered {
  std::vector<Scan> scans;
  PointCloud cloud;
  std::vector<int32_t> scan_of_point;
  std::vector<int64_t> cell_of_point;
};

Gathered Gather(const std::vector<std::string>& paths) {
  Gathered g;
  for (const std::string& path : paths) {
    for (const Scan& scan : ReadScanFileAndWarn(path).scans) {
      std::vector<int64_t> cells;
      const PointCloud cloud = ToPointCloud(scan, true, &cells);
      g.cloud = g.cloud.empty() ? cloud : MergeClouds({g.cloud, cloud});
      g.scan_of_point.insert(g.scan_of_point.end(), cloud.size(), static_cast<int32_t>(g.scans.size()));
      g.cell_of_point.insert(g.cell_of_point.end(), cells.begin(), cells.end());
      g.scans.push_back(scan);
    }
  }
  if (g.cloud.empty()) throw InputError("the inputs hold no points");
  return g;
}

std::vector<Scan> KeepCells(const Gathered& g, const std::vector<uint8_t>& keep) {
  std::vector<Scan> out;
  for (size_t s = 0; s < g.scans.size(); ++s) {
    std::vector<int64_t> cells;
    std::vector<uint8_t> flags;
    for (size_t i = 0; i < keep.size(); ++i) {
      if (g.scan_of_point[i] != static_cast<int32_t>(s)) continue;
      cells.push_back(g.cell_of_point[i]);
      flags.push_back(keep[i]);
    }
    out.push_back(KeepScanCells(g.scans[s], cells, flags));
  }
  return out;
}

std::vector<Scan> WithLabels(const Gathered& g, const std::vector<int32_t>& labels) {
  std::vector<Scan> out;
  for (const Scan& scan : g.scans) {
    Scan labelled = scan;
    labelled.label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
    out.push_back(labelled);
  }
  for (size_t i = 0; i < labels.size(); ++i) {
    Scan& scan = out[g.scan_of_point[i]];
    scan.label.at<int32_t>(static_cast<int>(g.cell_of_point[i] / scan.cols), g.cell_of_point[i] % scan.cols) =
        labels[i];
  }
  return out;
}

// World-frame normals into each scan's normal channel (scanner frame), facing that scan's scanner, and
// their curvature into the curvature channel (NaN where a point had too few neighbours).
std::vector<Scan> WithNormals(const Gathered& g, const NormalResult& result) {
  const std::vector<Eigen::Vector3f>& normals_in_world = result.normals;
  std::vector<Scan> out;
  for (const Scan& scan : g.scans) {
    Scan with = scan;
    with.normal = cv::Mat(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0));
    with.curvature = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(NAN));
    out.push_back(with);
  }
  for (size_t i = 0; i < normals_in_world.size(); ++i) {
    Scan& scan = out[g.scan_of_point[i]];
    const Eigen::Matrix3f scanner_from_world =
        scan.world_from_scanner.topLeftCorner<3, 3>().transpose().cast<float>();
    const int row = static_cast<int>(g.cell_of_point[i] / scan.cols), col = g.cell_of_point[i] % scan.cols;
    Eigen::Vector3f n = scanner_from_world * normals_in_world[i];
    const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
    if (n.dot(Eigen::Vector3f(p[0], p[1], p[2])) > 0.0f) n = -n;
    scan.normal.at<cv::Vec3f>(row, col) = cv::Vec3f(n.x(), n.y(), n.z());
    if (normals_in_world[i].squaredNorm() > 0.0f) scan.curvature.at<float>(row, col) = result.curvature[i];
  }
  return out;
}

// The gathered cloud with normals for a Poisson reconstruction: its own when every scan has them, else
// estimated from the `neighbors` nearest points, each turned toward the scanner of the scan it came from
// (several scans see a surface from several sides; one viewpoint would flip some of them).
PointCloud WithOrientedNormals(const Gathered& g, int neighbors, bool* estimated) {
  PointCloud cloud = g.cloud;
  *estimated = cloud.normals.size() != cloud.size();
  if (!*estimated) return cloud;
  NormalOptions options;
  options.neighbors = neighbors;
  cloud.normals = EstimateNormals(cloud, options).normals;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f scanner_in_world =
        g.scans[g.scan_of_point[i]].world_from_scanner.topRightCorner<3, 1>().cast<float>();
    if (cloud.normals[i].dot(scanner_in_world - cloud.points[i]) < 0.0f) cloud.normals[i] = -cloud.normals[i];
  }
  return cloud;
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
      "Point-set tools over scans and clouds (docs/points.md). OPERATION: outliers | voxel | sample | crop | "
      "transform | merge | normals | planes | cluster | kmeans | mesh | regions | superpixels | sample-mesh "
      "(IN = a triangle mesh). Scans keep their grid where the operation allows.",
      "points"};
  std::string operation, output_path, json_path, method;
  std::vector<std::string> inputs;
  std::string box_text, polygon_text, matrix_text;
  bool grid = false, hough = false;
  double voxel_m = 0.05, max_angle_deg = 10.0;
  int64_t count = 100000;
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
  app.add_option("--method", method,
                 "outliers: statistical (default) | radius; mesh: grid (default: the scans' grid mesh) | "
                 "poisson | scale-space (surface reconstruction)");
  app.add_option("--voxel", voxel_m, "voxel: cube side, metres")->capture_default_str();
  app.add_option("--count", count, "sample: points to keep; sample-mesh: points to draw")
      ->capture_default_str();
  app.add_option("--box", box_text, "crop: xmin,ymin,zmin,xmax,ymax,zmax (world, metres)");
  app.add_option("--polygon", polygon_text, "crop: x1,y1,x2,y2,... (world xy, metres)");
  app.add_option("--matrix", matrix_text,
                 "transform: new_world_from_world as 16 comma-separated numbers (row major), "
                 "x,y,z,yaw_deg[,pitch_deg,roll_deg] or a pose file (as verify --pose)");
  app.add_flag("--grid", grid, "normals: from the scan grid instead of a KD-tree");
  app.add_flag("--hough", hough, "planes: Hough detection (ball accumulator) instead of RANSAC");
  app.add_option("--max-angle", max_angle_deg, "regions: largest normal angle between neighbours, degrees")
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
        const std::string mesh_method = method.empty() ? "grid" : method;
        if (operation == "mesh" && mesh_method != "grid") {
          if (mesh_method != "poisson" && mesh_method != "scale-space")
            throw OptionsError(
                fmt::format("--method '{}': mesh takes grid, poisson or scale-space", mesh_method));
          points.surface.method = ParseEnum<SurfaceMethod>(mesh_method);
        }
        binder.Validate(points);
        const uint64_t seed = points.planes.seed;
        StatisticalOutlierOptions& statistical = points.statistical;
        RadiusOutlierOptions& radius_outliers = points.radius;
        CropOptions& crop = points.crop;
        NormalOptions& normals = points.normals;
        RansacPlaneOptions& planes = points.planes;
        HoughPlaneOptions& hough_options = points.hough;
        EuclideanClusterOptions& clusters = points.cluster;
        KMeansOptions& kmeans = points.kmeans;
        ScanMeshOptions& mesh_options = points.mesh;
        RegionGrowingOptions& region_options = points.regions;
        SuperpixelOptions& superpixel_options = points.superpixels;
        CheckOutputs(output_path, json_path, inputs);
        if (operation == "mesh" && FileExtension(output_path) != "ply") {
          throw OptionsError(fmt::format("-o {}: mesh writes a triangle mesh, as .ply", output_path));
        }
        if ((operation == "voxel" || operation == "merge") && FileExtension(output_path) != "ply") {
          throw OptionsError(fmt::format("-o {}: {} writes a plain cloud, as .ply", output_path, operation));
        }
        const std::vector<double> box = ParseNumbers(box_text, "--box"),
                                  polygon = ParseNumbers(polygon_text, "--polygon");
        if (!box.empty() && box.size() != 6)
          throw OptionsError("--box needs 6 numbers: xmin,ymin,zmin,xmax,ymax,zmax");
        if (operation == "sample-mesh") {
          // Uniform (area-weighted) samples of a triangle mesh (pointset/sampling.h), with the triangles'
          // normals.
          if (inputs.size() != 1) throw OptionsError("sample-mesh takes one mesh (.ply, .obj)");
          if (FileExtension(output_path) != "ply")
            throw OptionsError(fmt::format("-o {}: sample-mesh writes .ply", output_path));
          CheckOption(count > 0, fmt::format("--count must be > 0, got {}", count));
          // Before reading the mesh: the samples, and the written cloud's copy of them.
          CheckMemoryBudget(SaturatingBytes(count, 2 * kSurfaceSampleBytes),
                            fmt::format("--count {}: sampling {} points", count, count));
          const TriangleMesh mesh = ReadMeshAndWarn(inputs[0]);
          if (mesh.empty()) throw InputError(fmt::format("{}: the mesh has no triangles", inputs[0]));
          const Timer timer;
          SurfaceSamples samples = SampleSurface(mesh, count, seed);
          PointCloud cloud;
          cloud.points = std::move(samples.points);
          cloud.normals = std::move(samples.normals);
          const double seconds = timer.Seconds();
          WritePointCloud(output_path, cloud);
          nlohmann::ordered_json summary = {{"operation", operation},
                                            {"triangles", mesh.num_triangles()},
                                            {"output_points", cloud.size()},
                                            {"seconds", seconds}};
          WriteJsonOutput(json_path, CommandJson(UsedOptions(points, operation), summary));
          Summarize(fmt::format("sample-mesh: {} points from {} triangles -> {}", cloud.size(),
                                mesh.num_triangles(), output_path));
          return 0;
        }
        const Timer read_timer;
        const Gathered g = Gather(inputs);
        nlohmann::ordered_json summary = {{"operation", operation},
                                          {"input_points", g.cloud.size()},
                                          {"scans", g.scans.size()},
                                          {"read_seconds", read_timer.Seconds()}};
        const Timer timer;  // the operation alone, without reading and writing
        std::vector<Scan> scans_out;
        PointCloud cloud_out;
        bool as_cloud = false;
        if (operation == "outliers" || operation == "crop" || operation == "sample") {
          std::vector<uint8_t> keep;
          if (operation == "outliers" && (method.empty() || method == "statistical")) {
            keep = StatisticalOutlierInliers(g.cloud, statistical);
          } else if (operation == "outliers" && method == "radius") {
            keep = RadiusOutlierInliers(g.cloud, radius_outliers);
          } else if (operation == "outliers") {
            throw OptionsError(fmt::format("--method '{}': expected statistical or radius", method));
          } else if (operation == "sample") {
            keep = RandomSampleInliers(g.cloud, count, seed);
          } else {
            if (!box.empty())
              crop.box = Eigen::AlignedBox3f(Eigen::Vector3f(box[0], box[1], box[2]),
                                             Eigen::Vector3f(box[3], box[4], box[5]));
            if (polygon.size() % 2) throw OptionsError("--polygon needs x y pairs");
            for (size_t i = 0; i + 1 < polygon.size(); i += 2)
              crop.polygon.emplace_back(polygon[i], polygon[i + 1]);
            keep = CropInliers(g.cloud, crop);
          }
          scans_out = KeepCells(g, keep);
          summary["output_points"] = std::count(keep.begin(), keep.end(), 1);
        } else if (operation == "voxel") {
          cloud_out = VoxelDownsample(g.cloud, voxel_m);
          as_cloud = true;
        } else if (operation == "merge") {
          cloud_out = g.cloud;
          as_cloud = true;
        } else if (operation == "mesh") {
          // grid: the grid mesh of any organized scan, real ones included (scanner/scan_mesh.h); otherwise a
          // surface reconstructed from all the points in the world frame (pointset/surface.h).
          TriangleMesh mesh;
          summary["method"] = mesh_method;
          if (mesh_method == "grid") {
            for (const Scan& scan : g.scans) AppendMesh(ScanToMesh(scan, mesh_options), &mesh);
            if (mesh.empty()) {
              throw InputError(
                  fmt::format("{}: the grid mesh has no triangles (no two neighbouring cells are joined; a "
                              "plain cloud has no grid): use --method poisson or scale-space",
                              fmt::join(inputs, ", ")));
            }
          } else if (points.surface.method == SurfaceMethod::kPoisson) {
            bool estimated = false;
            const PointCloud cloud = WithOrientedNormals(g, points.surface.normal_neighbors, &estimated);
            summary["normals"] = estimated ? "estimated" : "input";
            mesh = ReconstructSurface(cloud, points.surface);
          } else {
            mesh = ReconstructSurface(g.cloud, points.surface);
          }
          summary["seconds"] = timer.Seconds();
          summary["vertices"] = mesh.num_vertices();
          summary["triangles"] = mesh.num_triangles();
          WriteMesh(output_path, mesh);
          WriteJsonOutput(json_path, CommandJson(UsedOptions(points, operation, mesh_method), summary));
          Summarize(fmt::format("mesh ({}): {} vertices, {} triangles from {} points -> {}", mesh_method,
                                mesh.num_vertices(), mesh.num_triangles(), g.cloud.size(), output_path));
          return 0;
        } else if (operation == "regions" || operation == "superpixels") {
          // Per scan, over its grid: labels into the scan's label channel.
          int total = 0;
          for (const Scan& scan : g.scans) {
            Scan labelled = scan;
            int count = 0;
            if (operation == "regions") {
              const Scan with_normals = scan.normal.empty() ? WithGridNormals(scan, normals) : scan;
              labelled.label = SegmentByRegionGrowing(
                  scan, region_options, NormalAngleCondition(with_normals, max_angle_deg), &count);
            } else {
              labelled.label = ScanSuperpixels(scan, superpixel_options, &count);
            }
            total += count;
            scans_out.push_back(labelled);
          }
          summary[operation] = total;
        } else if (operation == "transform") {
          if (matrix_text.empty()) throw OptionsError("transform needs --matrix");
          const Eigen::Matrix4d new_from_world = lidarshop::ParsePose(matrix_text, "--matrix");
          for (const Scan& scan : g.scans) scans_out.push_back(TransformScan(scan, new_from_world));
        } else if (operation == "normals") {
          if (grid) {
            for (const Scan& scan : g.scans) scans_out.push_back(WithGridNormals(scan, normals));
          } else {
            scans_out = WithNormals(g, EstimateNormals(g.cloud, normals));
          }
        } else if (operation == "planes") {
          hough_options.distance_step_m = 2.0 * planes.distance_threshold_m;  // inliers within half a cell
          hough_options.max_planes = planes.max_planes;
          hough_options.min_inliers = std::max<int64_t>(3, planes.min_inliers);
          const std::vector<PlaneFit> fits =
              hough ? DetectPlanesHough(g.cloud, hough_options) : DetectPlanesRansac(g.cloud, planes);
          std::vector<int32_t> labels(g.cloud.size(), kNoLabel);
          summary["planes"] = nlohmann::ordered_json::array();
          for (size_t p = 0; p < fits.size(); ++p) {
            for (uint32_t i : fits[p].inliers) labels[i] = static_cast<int32_t>(p);
            summary["planes"].push_back(
                {{"normal", {fits[p].normal.x(), fits[p].normal.y(), fits[p].normal.z()}},
                 {"offset_m", fits[p].offset_m},
                 {"inliers", fits[p].inliers.size()},
                 {"rms_m", fits[p].rms_m}});
          }
          scans_out = WithLabels(g, labels);
        } else if (operation == "cluster") {
          const ClusterResult result = EuclideanClusters(g.cloud, clusters);
          summary["clusters"] = result.num_clusters();
          summary["cluster_sizes"] = result.sizes;
          scans_out = WithLabels(g, result.labels);
        } else if (operation == "kmeans") {
          const KMeansResult result = KMeans(g.cloud, kmeans);
          summary["inertia_m2"] = result.inertia_m2;
          summary["iterations"] = result.iterations;
          scans_out = WithLabels(g, result.labels);
        } else {
          throw OptionsError(
              fmt::format("unknown operation '{}' (outliers, voxel, sample, crop, transform, merge, "
                          "normals, planes, cluster, kmeans, mesh, regions, superpixels, sample-mesh)",
                          operation));
        }
        summary["seconds"] = timer.Seconds();
        if (as_cloud) {
          WritePointCloud(output_path, cloud_out);
          summary["output_points"] = cloud_out.size();
        } else {
          WriteScanFile(output_path, scans_out);
        }
        WriteJsonOutput(json_path, CommandJson(UsedOptions(points, operation), summary));
        Summarize(PointsSummary(summary, output_path));
        return 0;
      },
      &binder);
}

}  // namespace lidarshop::cli
