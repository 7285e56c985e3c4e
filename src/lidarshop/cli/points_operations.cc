#include "lidarshop/cli/points_operations.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/util/error.h"
#include "lidarshop/verify/pose_text.h"

namespace lidarshop::cli {
namespace {

using Json = nlohmann::ordered_json;

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

// Operations that keep or drop points: the kept cells of every scan.
PointsOutput Kept(const Gathered& g, const std::vector<uint8_t>& keep, Json* summary) {
  (*summary)["output_points"] = std::count(keep.begin(), keep.end(), 1);
  return {.scans = KeepCells(g, keep)};
}

PointsOutput Outliers(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                      Json* s) {
  if (f.method.empty() || f.method == "statistical")
    return Kept(g, StatisticalOutlierInliers(g.cloud, o.statistical), s);
  if (f.method == "radius") return Kept(g, RadiusOutlierInliers(g.cloud, o.radius), s);
  throw OptionsError(fmt::format("--method '{}': expected statistical or radius", f.method));
}

PointsOutput Sample(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
  return Kept(g, RandomSampleInliers(g.cloud, f.count, o.planes.seed), s);
}

PointsOutput Crop(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
  if (!f.box.empty())
    o.crop.box = Eigen::AlignedBox3f(Eigen::Vector3f(f.box[0], f.box[1], f.box[2]),
                                     Eigen::Vector3f(f.box[3], f.box[4], f.box[5]));
  if (f.polygon.size() % 2) throw OptionsError("--polygon needs x y pairs");
  for (size_t i = 0; i + 1 < f.polygon.size(); i += 2)
    o.crop.polygon.emplace_back(f.polygon[i], f.polygon[i + 1]);
  return Kept(g, CropInliers(g.cloud, o.crop), s);
}

PointsOutput Voxel(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags& f, Json*) {
  return {.cloud = VoxelDownsample(g.cloud, f.voxel_m)};
}

PointsOutput Merge(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags&, Json*) {
  return {.cloud = g.cloud};
}

PointsOutput Transform(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags& f, Json*) {
  if (f.matrix_text.empty()) throw OptionsError("transform needs --matrix");
  const Eigen::Matrix4d new_from_world = lidarshop::ParsePose(f.matrix_text, "--matrix");
  PointsOutput out;
  for (const Scan& scan : g.scans) out.scans.push_back(TransformScan(scan, new_from_world));
  return out;
}

PointsOutput Normals(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json*) {
  PointsOutput out;
  if (f.grid_normals) {
    for (const Scan& scan : g.scans) out.scans.push_back(WithGridNormals(scan, o.normals));
  } else {
    out.scans = WithNormals(g, EstimateNormals(g.cloud, o.normals));
  }
  return out;
}

PointsOutput Planes(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
  o.hough.distance_step_m = 2.0 * o.planes.distance_threshold_m;  // inliers within half a cell
  o.hough.max_planes = o.planes.max_planes;
  o.hough.min_inliers = std::max<int64_t>(3, o.planes.min_inliers);
  const std::vector<PlaneFit> fits =
      f.hough ? DetectPlanesHough(g.cloud, o.hough) : DetectPlanesRansac(g.cloud, o.planes);
  std::vector<int32_t> labels(g.cloud.size(), kNoLabel);
  (*s)["planes"] = Json::array();
  for (size_t p = 0; p < fits.size(); ++p) {
    for (uint32_t i : fits[p].inliers) labels[i] = static_cast<int32_t>(p);
    (*s)["planes"].push_back({{"normal", {fits[p].normal.x(), fits[p].normal.y(), fits[p].normal.z()}},
                              {"offset_m", fits[p].offset_m},
                              {"inliers", fits[p].inliers.size()},
                              {"rms_m", fits[p].rms_m}});
  }
  return {.scans = WithLabels(g, labels)};
}

PointsOutput Cluster(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags&, Json* s) {
  const ClusterResult result = EuclideanClusters(g.cloud, o.cluster);
  (*s)["clusters"] = result.num_clusters();
  (*s)["cluster_sizes"] = result.sizes;
  return {.scans = WithLabels(g, result.labels)};
}

PointsOutput KMeansOperation(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags&,
                             Json* s) {
  const KMeansResult result = KMeans(g.cloud, o.kmeans);
  (*s)["inertia_m2"] = result.inertia_m2;
  (*s)["iterations"] = result.iterations;
  return {.scans = WithLabels(g, result.labels)};
}

std::string MeshMethod(const PointsFlags& f) { return f.method.empty() ? "grid" : f.method; }

// grid: the grid mesh of any organized scan, real ones included (scan/scan_mesh.h); otherwise a surface
// reconstructed from all the points in the world frame (pointset/surface.h).
PointsOutput Mesh(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
  const std::string method = MeshMethod(f);
  PointsOutput out;
  (*s)["method"] = method;
  if (method == "grid") {
    for (const Scan& scan : g.scans) AppendMesh(ScanToMesh(scan, o.mesh), &out.mesh);
    if (out.mesh.empty()) {
      throw InputError(fmt::format(
          "{}: the grid mesh has no triangles (no two neighbouring cells are joined; a plain cloud "
          "has no grid): use --method poisson or scale-space",
          fmt::join(g.paths, ", ")));
    }
  } else if (o.surface.method == SurfaceMethod::kPoisson) {
    bool estimated = false;
    const PointCloud cloud = WithOrientedNormals(g, o.surface.normal_neighbors, &estimated);
    (*s)["normals"] = estimated ? "estimated" : "input";
    out.mesh = ReconstructSurface(cloud, o.surface);
  } else {
    out.mesh = ReconstructSurface(g.cloud, o.surface);
  }
  (*s)["seconds"] = 0.0;  // its place in the JSON, before the counts; the command sets the time
  (*s)["vertices"] = out.mesh.num_vertices();
  (*s)["triangles"] = out.mesh.num_triangles();
  return out;
}

// Per scan, over its grid: labels into the scan's label channel.
PointsOutput GridLabels(const Gathered& g, PointsOptions& o, const PointsFlags& f, Json* s, bool regions) {
  PointsOutput out;
  int total = 0;
  for (const Scan& scan : g.scans) {
    Scan labelled = scan;
    int count = 0;
    if (regions) {
      const Scan with_normals = scan.normal.empty() ? WithGridNormals(scan, o.normals) : scan;
      labelled.label = SegmentByRegionGrowing(scan, o.regions,
                                              NormalAngleCondition(with_normals, f.max_angle_deg), &count);
    } else {
      labelled.label = ScanSuperpixels(scan, o.superpixels, &count);
    }
    total += count;
    out.scans.push_back(labelled);
  }
  (*s)[regions ? "regions" : "superpixels"] = total;
  return out;
}

// Uniform (area-weighted) samples of a triangle mesh (pointset/sampling.h), with the triangles' normals.
PointsOutput SampleMesh(const Gathered&, const TriangleMesh& mesh, PointsOptions& o, const PointsFlags& f,
                        Json* s) {
  SurfaceSamples samples = SampleSurface(mesh, f.count, o.planes.seed);
  PointsOutput out;
  out.cloud.points = std::move(samples.points);
  out.cloud.normals = std::move(samples.normals);
  (*s)["triangles"] = mesh.num_triangles();
  (*s)["output_points"] = out.cloud.size();
  return out;
}

}  // namespace

const std::vector<PointsOperation>& PointsOperations() {
  using K = PointsOutputKind;
  static const std::vector<PointsOperation> operations = {
      {"outliers", K::kScans, false, {"statistical", "radius"}, Outliers},
      {"voxel", K::kCloud, false, {}, Voxel},
      {"sample", K::kScans, false, {}, Sample},
      {"crop", K::kScans, false, {"crop"}, Crop},
      {"transform", K::kScans, false, {}, Transform},
      {"merge", K::kCloud, false, {}, Merge},
      {"normals", K::kScans, false, {"normals"}, Normals},
      {"planes", K::kScans, false, {"planes", "hough"}, Planes},
      {"cluster", K::kScans, false, {"cluster"}, Cluster},
      {"kmeans", K::kScans, false, {"kmeans"}, KMeansOperation},
      {"mesh", K::kMesh, false, {"mesh", "surface"}, Mesh},
      {"regions",
       K::kScans,
       false,
       {"regions", "normals"},
       [](const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
         return GridLabels(g, o, f, s, /*regions=*/true);
       }},
      {"superpixels",
       K::kScans,
       false,
       {"superpixels"},
       [](const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, Json* s) {
         return GridLabels(g, o, f, s, /*regions=*/false);
       }},
      {"sample-mesh", K::kCloud, true, {}, SampleMesh},
  };
  return operations;
}

std::string PointsOperationNames(const std::string& separator) {
  std::vector<std::string> names;
  for (const PointsOperation& operation : PointsOperations()) names.push_back(operation.name);
  return fmt::format("{}", fmt::join(names, separator));
}

const PointsOperation& FindPointsOperation(const std::string& name) {
  for (const PointsOperation& operation : PointsOperations()) {
    if (operation.name == name) return operation;
  }
  throw OptionsError(fmt::format("unknown operation '{}' ({})", name, PointsOperationNames(", ")));
}

Gathered GatherScans(const std::vector<std::string>& paths) {
  Gathered g;
  g.paths = paths;
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

}  // namespace lidarshop::cli
