#include "lidarshop/cli/points_operations.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/sampling.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/verify/pose_text.h"

namespace lidarshop {
namespace {

constexpr const char* kSecondsDoc = "wall time of the operation alone";

}  // namespace

template <>
const StructInfo& InfoOf<cli::PointsRead>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsRead> b("PointsRead", "a points operation and the scans it read");
    b.Field(&cli::PointsRead::operation, "operation", "the operation's name");
    b.Field(&cli::PointsRead::input_points, "input_points", "points of every input scan");
    b.Field(&cli::PointsRead::scans, "scans", "input scans");
    b.Field(&cli::PointsRead::read_seconds, "read_seconds", "wall time reading them").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsKeptReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsKeptReport> b("PointsKeptReport", "points outliers | sample | crop --json");
    b.Flatten(&cli::PointsKeptReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsKeptReport::output_points, "output_points", "points kept");
    b.Field(&cli::PointsKeptReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsCloudReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsCloudReport> b("PointsCloudReport", "points voxel | merge --json");
    b.Flatten(&cli::PointsCloudReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsCloudReport::seconds, "seconds", kSecondsDoc).Unit("s");
    b.Field(&cli::PointsCloudReport::output_points, "output_points", "points of the cloud written");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsScansReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsScansReport> b("PointsScansReport", "points transform | normals --json");
    b.Flatten(&cli::PointsScansReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsScansReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsPlane>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsPlane> b("PointsPlane", "a plane found (normal · x + offset_m = 0)");
    b.Field(&cli::PointsPlane::normal, "normal", "unit normal, world frame");
    b.Field(&cli::PointsPlane::offset_m, "offset_m", "offset along the normal").Unit("m");
    b.Field(&cli::PointsPlane::inliers, "inliers", "points within the distance threshold");
    b.Field(&cli::PointsPlane::rms_m, "rms_m", "RMS distance of the inliers to the plane").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsPlanesReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsPlanesReport> b("PointsPlanesReport", "points planes --json");
    b.Flatten(&cli::PointsPlanesReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsPlanesReport::planes, "planes", "the planes, labels 0, 1, ... in the scans");
    b.Field(&cli::PointsPlanesReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsClusterReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsClusterReport> b("PointsClusterReport", "points cluster --json");
    b.Flatten(&cli::PointsClusterReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsClusterReport::clusters, "clusters", "clusters found");
    b.Field(&cli::PointsClusterReport::cluster_sizes, "cluster_sizes", "points per cluster, largest first");
    b.Field(&cli::PointsClusterReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsKMeansReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsKMeansReport> b("PointsKMeansReport", "points kmeans --json");
    b.Flatten(&cli::PointsKMeansReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsKMeansReport::inertia_m2, "inertia_m2", "sum of squared distances to the centres")
        .Unit("m2");
    b.Field(&cli::PointsKMeansReport::iterations, "iterations", "Lloyd iterations run");
    b.Field(&cli::PointsKMeansReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsMeshReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsMeshReport> b("PointsMeshReport", "points mesh --json");
    b.Flatten(&cli::PointsMeshReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsMeshReport::method, "method", "grid, poisson or scale-space");
    b.Field(&cli::PointsMeshReport::normals, "normals", "poisson: estimated or input");
    b.Field(&cli::PointsMeshReport::seconds, "seconds", kSecondsDoc).Unit("s");
    b.Field(&cli::PointsMeshReport::vertices, "vertices", "vertices of the mesh written");
    b.Field(&cli::PointsMeshReport::triangles, "triangles", "triangles of the mesh written");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsRegionsReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsRegionsReport> b("PointsRegionsReport", "points regions --json");
    b.Flatten(&cli::PointsRegionsReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsRegionsReport::regions, "regions", "regions over every scan's grid");
    b.Field(&cli::PointsRegionsReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsSuperpixelsReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsSuperpixelsReport> b("PointsSuperpixelsReport", "points superpixels --json");
    b.Flatten(&cli::PointsSuperpixelsReport::read);  // PointsRead's keys first
    b.Field(&cli::PointsSuperpixelsReport::superpixels, "superpixels", "superpixels over every scan's grid");
    b.Field(&cli::PointsSuperpixelsReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PointsSampleMeshReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PointsSampleMeshReport> b("PointsSampleMeshReport", "points sample-mesh --json");
    b.Field(&cli::PointsSampleMeshReport::operation, "operation", "sample-mesh");
    b.Field(&cli::PointsSampleMeshReport::triangles, "triangles", "triangles of the input mesh");
    b.Field(&cli::PointsSampleMeshReport::output_points, "output_points", "points drawn");
    b.Field(&cli::PointsSampleMeshReport::seconds, "seconds", kSecondsDoc).Unit("s");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop

namespace lidarshop::cli {
namespace {

// The summary lines of the reports: what the operation kept or found, of how many points.
std::string InputPoints(const PointsRead& read) {
  return fmt::format("{}: {} input points", read.operation, read.input_points);
}
std::string SummaryLine(const PointsKeptReport& r) {
  return fmt::format("{}, {} output points", InputPoints(r.read), r.output_points);
}
std::string SummaryLine(const PointsCloudReport& r) {
  return fmt::format("{}, {} output points", InputPoints(r.read), r.output_points);
}
std::string SummaryLine(const PointsScansReport& r) { return InputPoints(r.read); }
std::string SummaryLine(const PointsKMeansReport& r) { return InputPoints(r.read); }
std::string SummaryLine(const PointsPlanesReport& r) {
  return fmt::format("{}, {} planes", InputPoints(r.read), r.planes.size());
}
std::string SummaryLine(const PointsClusterReport& r) {
  return fmt::format("{}, {} clusters", InputPoints(r.read), r.clusters);
}
std::string SummaryLine(const PointsRegionsReport& r) {
  return fmt::format("{}, {} regions", InputPoints(r.read), r.regions);
}
std::string SummaryLine(const PointsSuperpixelsReport& r) {
  return fmt::format("{}, {} superpixels", InputPoints(r.read), r.superpixels);
}
std::string SummaryLine(const PointsMeshReport& r) {
  return fmt::format("mesh ({}): {} vertices, {} triangles from {} points", r.method, r.vertices, r.triangles,
                     r.read.input_points);
}
std::string SummaryLine(const PointsSampleMeshReport& r) {
  return fmt::format("{}: {} points from {} triangles", r.operation, r.output_points, r.triangles);
}

// `out` with the operation's report, timed now, and its summary line.
template <class R>
PointsOutput Reported(PointsOutput out, R report, const Timer& timer) {
  report.seconds = timer.Seconds();
  out.report = ToJson(report);
  out.summary_line = SummaryLine(report);
  return out;
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

// Operations that keep or drop points: the kept cells of every scan.
PointsOutput Kept(const Gathered& g, const std::vector<uint8_t>& keep, const PointsRead& r, const Timer& t) {
  const int64_t kept = std::count(keep.begin(), keep.end(), 1);
  return Reported({.scans = KeepCells(g, keep)}, PointsKeptReport{.read = r, .output_points = kept}, t);
}

PointsOutput Outliers(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                      const PointsRead& r, const Timer& t) {
  if (f.method.empty() || f.method == "statistical")
    return Kept(g, StatisticalOutlierInliers(g.cloud, o.statistical), r, t);
  if (f.method == "radius") return Kept(g, RadiusOutlierInliers(g.cloud, o.radius), r, t);
  throw OptionsError(fmt::format("--method '{}': expected statistical or radius", f.method));
}

PointsOutput Sample(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                    const PointsRead& r, const Timer& t) {
  return Kept(g, RandomSampleInliers(g.cloud, f.count, o.planes.seed), r, t);
}

PointsOutput Crop(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                  const PointsRead& r, const Timer& t) {
  if (!f.box.empty())
    o.crop.box = Eigen::AlignedBox3f(Eigen::Vector3f(f.box[0], f.box[1], f.box[2]),
                                     Eigen::Vector3f(f.box[3], f.box[4], f.box[5]));
  if (f.polygon.size() % 2) throw OptionsError("--polygon needs x y pairs");
  for (size_t i = 0; i + 1 < f.polygon.size(); i += 2)
    o.crop.polygon.emplace_back(f.polygon[i], f.polygon[i + 1]);
  return Kept(g, CropInliers(g.cloud, o.crop), r, t);
}

// Operations that write a plain cloud.
PointsOutput Cloud(PointCloud cloud, const PointsRead& r, const Timer& t) {
  const uint64_t points = cloud.size();
  return Reported({.cloud = std::move(cloud)}, PointsCloudReport{.read = r, .output_points = points}, t);
}

PointsOutput Voxel(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags& f,
                   const PointsRead& r, const Timer& t) {
  return Cloud(VoxelDownsample(g.cloud, f.voxel_m), r, t);
}

PointsOutput Merge(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags&,
                   const PointsRead& r, const Timer& t) {
  return Cloud(g.cloud, r, t);
}

PointsOutput Transform(const Gathered& g, const TriangleMesh&, PointsOptions&, const PointsFlags& f,
                       const PointsRead& r, const Timer& t) {
  if (f.matrix_text.empty()) throw OptionsError("transform needs --matrix");
  const Eigen::Matrix4d new_from_world = lidarshop::ParsePose(f.matrix_text, "--matrix");
  PointsOutput out;
  for (const Scan& scan : g.scans) out.scans.push_back(TransformScan(scan, new_from_world));
  return Reported(std::move(out), PointsScansReport{.read = r}, t);
}

PointsOutput Normals(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                     const PointsRead& r, const Timer& t) {
  PointsOutput out;
  if (f.grid_normals) {
    for (const Scan& scan : g.scans) out.scans.push_back(WithGridNormals(scan, o.normals));
  } else {
    out.scans = WithNormals(g, EstimateNormals(g.cloud, o.normals));
  }
  return Reported(std::move(out), PointsScansReport{.read = r}, t);
}

PointsOutput Planes(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                    const PointsRead& r, const Timer& t) {
  o.hough.distance_step_m = 2.0 * o.planes.distance_threshold_m;  // inliers within half a cell
  o.hough.max_planes = o.planes.max_planes;
  o.hough.min_inliers = std::max<int64_t>(3, o.planes.min_inliers);
  const std::vector<PlaneFit> fits =
      f.hough ? DetectPlanesHough(g.cloud, o.hough) : DetectPlanesRansac(g.cloud, o.planes);
  std::vector<int32_t> labels(g.cloud.size(), kNoLabel);
  PointsPlanesReport report{.read = r};
  for (size_t p = 0; p < fits.size(); ++p) {
    for (uint32_t i : fits[p].inliers) labels[i] = static_cast<int32_t>(p);
    report.planes.push_back({.normal = {fits[p].normal.x(), fits[p].normal.y(), fits[p].normal.z()},
                             .offset_m = fits[p].offset_m,
                             .inliers = fits[p].inliers.size(),
                             .rms_m = fits[p].rms_m});
  }
  return Reported({.scans = WithLabels(g, labels)}, std::move(report), t);
}

PointsOutput Cluster(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags&,
                     const PointsRead& r, const Timer& t) {
  const ClusterResult result = EuclideanClusters(g.cloud, o.cluster);
  return Reported(
      {.scans = WithLabels(g, result.labels)},
      PointsClusterReport{.read = r, .clusters = result.num_clusters(), .cluster_sizes = result.sizes}, t);
}

PointsOutput KMeansOperation(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags&,
                             const PointsRead& r, const Timer& t) {
  const KMeansResult result = KMeans(g.cloud, o.kmeans);
  return Reported(
      {.scans = WithLabels(g, result.labels)},
      PointsKMeansReport{.read = r, .inertia_m2 = result.inertia_m2, .iterations = result.iterations}, t);
}

std::string MeshMethod(const PointsFlags& f) { return f.method.empty() ? "grid" : f.method; }

// grid: the grid mesh of any organized scan, real ones included (scan/scan_mesh.h); otherwise a surface
// reconstructed from all the points in the world frame (pointset/surface.h).
PointsOutput Mesh(const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f,
                  const PointsRead& r, const Timer& t) {
  const std::string method = MeshMethod(f);
  PointsOutput out;
  PointsMeshReport report{.read = r, .method = method};
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
    report.normals = estimated ? "estimated" : "input";
    out.mesh = ReconstructSurface(cloud, o.surface);
  } else {
    out.mesh = ReconstructSurface(g.cloud, o.surface);
  }
  report.vertices = out.mesh.num_vertices();
  report.triangles = out.mesh.num_triangles();
  return Reported(std::move(out), std::move(report), t);
}

// Per scan, over its grid: labels into the scan's label channel.
PointsOutput GridLabels(const Gathered& g, PointsOptions& o, const PointsFlags& f, const PointsRead& r,
                        const Timer& t, bool regions) {
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
  if (regions) return Reported(std::move(out), PointsRegionsReport{.read = r, .regions = total}, t);
  return Reported(std::move(out), PointsSuperpixelsReport{.read = r, .superpixels = total}, t);
}

// Uniform (area-weighted) samples of a triangle mesh (pointset/sampling.h), with the triangles' normals.
PointsOutput SampleMesh(const Gathered&, const TriangleMesh& mesh, PointsOptions& o, const PointsFlags& f,
                        const PointsRead& r, const Timer& t) {
  SurfaceSamples samples = SampleSurface(mesh, f.count, o.planes.seed);
  PointsOutput out;
  out.cloud.points = std::move(samples.points);
  out.cloud.normals = std::move(samples.normals);
  const PointsSampleMeshReport report{
      .operation = r.operation, .triangles = mesh.num_triangles(), .output_points = out.cloud.size()};
  return Reported(std::move(out), report, t);
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
       [](const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, const PointsRead& r,
          const Timer& t) { return GridLabels(g, o, f, r, t, /*regions=*/true); }},
      {"superpixels",
       K::kScans,
       false,
       {"superpixels"},
       [](const Gathered& g, const TriangleMesh&, PointsOptions& o, const PointsFlags& f, const PointsRead& r,
          const Timer& t) { return GridLabels(g, o, f, r, t, /*regions=*/false); }},
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
