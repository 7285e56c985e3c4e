// lidarshop points / register: the point-set toolbox over scans and clouds (pointset/*.h, docs/points.md).
//
//   lidarshop points OPERATION IN... -o OUT [options] [--json FILE|-]
//   lidarshop register FIXED MOVING -o OUT [--max-distance M] [--json FILE|-]
//
// Every input scan is taken in the world frame and the operation sees all of them as one cloud. Operations
// that drop points (outliers, crop, sample) or label them (planes, cluster, kmeans) or give normals keep
// every scan's grid: dropped cells become cells without a return, labels and normals go into the scans'
// channels. Operations that make new points (voxel, merge) write a plain cloud (.ply / .pcd) in the world
// frame.
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/scanner/scan_mesh.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {
namespace {

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
    for (const Scan& scan : ReadScanFile(path).scans) {
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

// World-frame normals into each scan's normal channel (scanner frame), facing that scan's scanner.
std::vector<Scan> WithNormals(const Gathered& g, const std::vector<Eigen::Vector3f>& normals_in_world) {
  std::vector<Scan> out;
  for (const Scan& scan : g.scans) {
    Scan with = scan;
    with.normal = cv::Mat(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0));
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
  }
  return out;
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

void WriteSummary(const std::string& path, const nlohmann::json& json) {
  if (path.empty()) return;
  if (path == "-") {
    std::cout << json.dump(2) << "\n";
  } else {
    WriteFileAtomically(path, [&](std::ostream& out) { out << json.dump(2) << "\n"; });
  }
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
  std::string operation, output_path, json_path, method = "statistical";
  std::vector<std::string> inputs;
  StatisticalOutlierOptions statistical;
  RadiusOutlierOptions radius_outliers;
  CropOptions crop;
  std::string box_text, polygon_text, matrix_text;
  NormalOptions normals;
  bool grid = false;
  RansacPlaneOptions planes;
  HoughPlaneOptions hough_options;
  bool hough = false;
  EuclideanClusterOptions clusters;
  KMeansOptions kmeans;
  double voxel_m = 0.05;
  ScanMeshOptions mesh_options;
  RegionGrowingOptions region_options;
  double max_angle_deg = 10.0;
  SuperpixelOptions superpixel_options;
  std::string superpixel_method = "slic";
  mesh_options.world_frame = true;
  int64_t count = 100000;
  uint64_t seed = 1;
  app.add_option("operation", operation, "the tool")->required();
  app.add_option("inputs", inputs, "scan or cloud files (.ptx, .e57, .ply, .pcd, .las, .xyz, .pts)")
      ->required();
  app.add_option("-o,--output", output_path, "output file; a scan format keeps the grid")->required();
  app.add_option("--json", json_path, "write a summary as JSON to FILE, or '-' for stdout");
  app.add_option("--method", method, "outliers: statistical | radius")->capture_default_str();
  app.add_option("--neighbors", statistical.neighbors, "outliers/normals: k nearest")->capture_default_str();
  app.add_option("--std-ratio", statistical.std_ratio, "statistical outliers: threshold in σ")
      ->capture_default_str();
  app.add_option("--radius", radius_outliers.radius_m, "outliers, normals, cluster: radius, metres")
      ->capture_default_str();
  app.add_option("--min-neighbors", radius_outliers.min_neighbors, "radius outliers")->capture_default_str();
  app.add_option("--voxel", voxel_m, "voxel: cube side, metres")->capture_default_str();
  app.add_option("--count", count, "sample: points to keep; sample-mesh: points to draw")
      ->capture_default_str();
  app.add_option("--seed", seed, "sample, planes, kmeans: seed")->capture_default_str();
  app.add_option("--box", box_text, "crop: xmin,ymin,zmin,xmax,ymax,zmax (world, metres)");
  app.add_option("--polygon", polygon_text, "crop: x1,y1,x2,y2,... (world xy, metres)");
  app.add_option("--labels", crop.labels, "crop: keep these labels");
  app.add_option("--min-range", crop.min_range_m, "crop: metres from the world origin")
      ->capture_default_str();
  app.add_option("--max-range", crop.max_range_m, "crop: metres (0 = none)")->capture_default_str();
  app.add_option("--min-intensity", crop.min_intensity, "crop")->capture_default_str();
  app.add_option("--max-intensity", crop.max_intensity, "crop")->capture_default_str();
  app.add_flag("--invert", crop.invert, "crop: keep the points outside instead");
  app.add_option("--matrix", matrix_text,
                 "transform: 16 comma-separated numbers, row major, new_world_from_world");
  app.add_flag("--grid", grid, "normals: from the scan grid instead of a KD-tree");
  app.add_option("--window", normals.window_cells, "normals --grid: half-width, cells")
      ->capture_default_str();
  app.add_option("--distance", planes.distance_threshold_m, "planes: inlier distance, metres")
      ->capture_default_str();
  app.add_option("--iterations", planes.max_iterations, "planes: RANSAC hypotheses at most")
      ->capture_default_str();
  app.add_flag("--hough", hough, "planes: Hough detection (ball accumulator) instead of RANSAC");
  app.add_option("--angle-step", hough_options.angle_step_deg, "planes --hough: normal resolution, degrees")
      ->capture_default_str();
  app.add_option("--planes", planes.max_planes, "planes: how many, sequentially")->capture_default_str();
  app.add_option("--min-inliers", planes.min_inliers, "planes: stop below this")->capture_default_str();
  app.add_option("--min-points", clusters.min_points, "cluster: smaller clusters are noise")
      ->capture_default_str();
  app.add_option("--mesh-jump", mesh_options.max_range_jump_ratio,
                 "mesh: drop edges whose ranges differ by more than this fraction of the nearer range")
      ->capture_default_str();
  app.add_option("--max-angle", max_angle_deg, "regions: largest normal angle between neighbours, degrees")
      ->capture_default_str();
  app.add_option("--min-cells", region_options.min_region_cells, "regions: smaller regions get no label")
      ->capture_default_str();
  app.add_option("--superpixel-method", superpixel_method, "superpixels: slic | graph")
      ->capture_default_str();
  app.add_option("--region-cells", superpixel_options.region_cells, "superpixels (slic): side, cells")
      ->capture_default_str();
  app.add_option("--k", kmeans.clusters, "kmeans: clusters")->capture_default_str();
  return RunCommand(app, argc, argv, [&]() {
    CheckOutputs(output_path, json_path, inputs);
    if (operation == "mesh" && FileExtension(output_path) != "ply") {
      throw OptionsError(fmt::format("-o {}: mesh writes a triangle mesh, as .ply", output_path));
    }
    if ((operation == "voxel" || operation == "merge") && FileExtension(output_path) != "ply") {
      throw OptionsError(fmt::format("-o {}: {} writes a plain cloud, as .ply", output_path, operation));
    }
    const std::vector<double> box = ParseNumbers(box_text, "--box"),
                              polygon = ParseNumbers(polygon_text, "--polygon"),
                              matrix = ParseNumbers(matrix_text, "--matrix");
    if (!box.empty() && box.size() != 6)
      throw OptionsError("--box needs 6 numbers: xmin,ymin,zmin,xmax,ymax,zmax");
    if (operation == "sample-mesh") {
      // Uniform (area-weighted) samples of a triangle mesh (pointset/sampling.h), with the triangles'
      // normals.
      if (inputs.size() != 1) throw OptionsError("sample-mesh takes one mesh (.ply, .obj)");
      if (FileExtension(output_path) != "ply")
        throw OptionsError(fmt::format("-o {}: sample-mesh writes .ply", output_path));
      const TriangleMesh mesh = ReadMesh(inputs[0]);
      if (mesh.empty()) throw InputError(fmt::format("{}: the mesh has no triangles", inputs[0]));
      CheckOption(count > 0, fmt::format("--count must be > 0, got {}", count));
      const Timer timer;
      SurfaceSamples samples = SampleSurface(mesh, count, seed);
      PointCloud cloud;
      cloud.points = std::move(samples.points);
      cloud.normals = std::move(samples.normals);
      const double seconds = timer.Seconds();
      WritePointCloud(output_path, cloud);
      WriteSummary(json_path, {{"operation", operation},
                               {"triangles", mesh.num_triangles()},
                               {"output_points", cloud.size()},
                               {"seconds", seconds}});
      return 0;
    }
    const Timer read_timer;
    const Gathered g = Gather(inputs);
    nlohmann::json summary = {{"operation", operation},
                              {"input_points", g.cloud.size()},
                              {"scans", g.scans.size()},
                              {"read_seconds", read_timer.Seconds()}};
    const Timer timer;  // the operation alone, without reading and writing
    std::vector<Scan> scans_out;
    PointCloud cloud_out;
    bool as_cloud = false;
    if (operation == "outliers" || operation == "crop" || operation == "sample") {
      std::vector<uint8_t> keep;
      if (operation == "outliers" && method == "statistical") {
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
      // The grid mesh of any organized scan, real ones included (scanner/scan_mesh.h).
      TriangleMesh mesh;
      for (const Scan& scan : g.scans) AppendMesh(ScanToMesh(scan, mesh_options), &mesh);
      summary["seconds"] = timer.Seconds();
      summary["triangles"] = mesh.num_triangles();
      WriteMesh(output_path, mesh);
      WriteSummary(json_path, summary);
      return 0;
    } else if (operation == "regions" || operation == "superpixels") {
      // Per scan, over its grid: labels into the scan's label channel.
      int total = 0;
      for (const Scan& scan : g.scans) {
        Scan labelled = scan;
        int count = 0;
        if (operation == "regions") {
          const Scan with_normals = scan.normal.empty() ? WithGridNormals(scan, normals) : scan;
          labelled.label = SegmentByRegionGrowing(scan, region_options,
                                                  NormalAngleCondition(with_normals, max_angle_deg), &count);
        } else {
          if (superpixel_method != "slic" && superpixel_method != "graph") {
            throw OptionsError(
                fmt::format("--superpixel-method '{}': expected slic or graph", superpixel_method));
          }
          superpixel_options.method =
              superpixel_method == "slic" ? SuperpixelMethod::kSlic : SuperpixelMethod::kGraph;
          labelled.label = ScanSuperpixels(scan, superpixel_options, &count);
          labelled.label.setTo(kNoLabel, scan.valid == 0);
        }
        total += count;
        scans_out.push_back(labelled);
      }
      summary[operation] = total;
    } else if (operation == "transform") {
      if (matrix.size() != 16) throw OptionsError("transform needs --matrix with 16 numbers");
      const Eigen::Matrix4d new_from_world =
          Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(matrix.data());
      for (const Scan& scan : g.scans) scans_out.push_back(TransformScan(scan, new_from_world));
    } else if (operation == "normals") {
      normals.neighbors = statistical.neighbors;
      if (app.count("--radius")) normals.radius_m = radius_outliers.radius_m;
      if (grid) {
        for (const Scan& scan : g.scans) scans_out.push_back(WithGridNormals(scan, normals));
      } else {
        scans_out = WithNormals(g, EstimateNormals(g.cloud, normals).normals);
      }
    } else if (operation == "planes") {
      planes.seed = seed;
      hough_options.distance_step_m = 2.0 * planes.distance_threshold_m;  // inliers within half a cell
      hough_options.max_planes = planes.max_planes;
      hough_options.min_inliers = std::max<int64_t>(3, planes.min_inliers);
      hough_options.seed = seed;
      const std::vector<PlaneFit> fits =
          hough ? DetectPlanesHough(g.cloud, hough_options) : DetectPlanesRansac(g.cloud, planes);
      std::vector<int32_t> labels(g.cloud.size(), kNoLabel);
      summary["planes"] = nlohmann::json::array();
      for (size_t p = 0; p < fits.size(); ++p) {
        for (uint32_t i : fits[p].inliers) labels[i] = static_cast<int32_t>(p);
        summary["planes"].push_back({{"normal", {fits[p].normal.x(), fits[p].normal.y(), fits[p].normal.z()}},
                                     {"offset_m", fits[p].offset_m},
                                     {"inliers", fits[p].inliers.size()},
                                     {"rms_m", fits[p].rms_m}});
      }
      scans_out = WithLabels(g, labels);
    } else if (operation == "cluster") {
      clusters.radius_m = radius_outliers.radius_m;
      const ClusterResult result = EuclideanClusters(g.cloud, clusters);
      summary["clusters"] = result.num_clusters();
      summary["cluster_sizes"] = result.sizes;
      scans_out = WithLabels(g, result.labels);
    } else if (operation == "kmeans") {
      kmeans.seed = seed;
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
    WriteSummary(json_path, summary);
    return 0;
  });
}

int RunRegister(int argc, char** argv) {
  CLI::App app{
      "Register MOVING onto FIXED by point-to-plane ICP from MOVING's pose (docs/points.md); writes MOVING "
      "with its world_from_scanner corrected.",
      "register"};
  std::string fixed_path, moving_path, output_path, json_path;
  IcpOptions options;
  GlobalAlignOptions global;
  bool use_global = false;
  app.add_flag("--global", use_global, "no usable pose: align FPFH features by RANSAC first");
  app.add_option("--voxel", global.voxel_m, "--global: voxel size of the feature clouds, metres")
      ->capture_default_str();
  app.add_option("--feature-radius", global.feature_radius_m, "--global: FPFH radius, metres")
      ->capture_default_str();
  app.add_option("--seed", global.seed, "--global: RANSAC seed")->capture_default_str();
  app.add_option("fixed", fixed_path, "the scan that stays (its first scan)")->required();
  app.add_option("moving", moving_path, "the scan to move (its first scan)")->required();
  app.add_option("-o,--output", output_path, "the moving scan with its new pose")->required();
  app.add_option("--json", json_path, "write a summary as JSON to FILE, or '-' for stdout");
  app.add_option("--max-distance", options.max_correspondence_m, "first pairing distance, metres")
      ->capture_default_str();
  app.add_option("--min-distance", options.min_correspondence_m, "final pairing distance, metres")
      ->capture_default_str();
  app.add_option("--iterations", options.max_iterations, "ICP iterations at most")->capture_default_str();
  return RunCommand(app, argc, argv, [&]() {
    options.Check();
    if (use_global) global.Check();
    CheckOutputs(output_path, json_path, {fixed_path, moving_path});
    const Timer timer;
    const ScanFile fixed = ReadScanFile(fixed_path), moving = ReadScanFile(moving_path);
    if (fixed.scans.empty() || moving.scans.empty()) throw InputError("register: an input holds no scan");
    const ScanRegistration result =
        RegisterScans(fixed.scans[0], moving.scans[0], options, use_global ? &global : nullptr);
    WriteScanFile(output_path, {result.registered});
    std::vector<std::vector<double>> rows;
    for (int r = 0; r < 4; ++r) {
      rows.push_back({result.registered.world_from_scanner(r, 0), result.registered.world_from_scanner(r, 1),
                      result.registered.world_from_scanner(r, 2),
                      result.registered.world_from_scanner(r, 3)});
    }
    WriteSummary(json_path, {{"world_from_scanner", rows},
                             {"rms_m", result.icp.rms_m},
                             {"fitness", result.icp.fitness},
                             {"iterations", result.icp.iterations},
                             {"converged", result.icp.converged},
                             {"seconds", timer.Seconds()}});
    return 0;
  });
}

}  // namespace lidarshop::cli
