// The operations of `lidarshop points` as one table (docs/points.md): each names the PointsOptions members it
// uses, what it writes, and the function that runs it on the gathered inputs. The command parses, gathers,
// looks the operation up and writes what it returns; the help text, the "unknown operation" message and the
// options reported in --json all come from the table. CLI-internal.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/pointset/surface.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/util/options_fwd.h"
#include "lidarshop/util/timer.h"

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
const StructInfo& InfoOf<cli::PointsOptions>();  // points_command.cc
}  // namespace lidarshop

namespace lidarshop::cli {

// The command's own flags that are no library option.
struct PointsFlags {
  std::string method;           // outliers: statistical | radius; mesh: grid | poisson | scale-space
  std::vector<double> box;      // crop: xmin,ymin,zmin,xmax,ymax,zmax (world, metres), empty = none
  std::vector<double> polygon;  // crop: x1,y1,x2,y2,... (world xy, metres)
  std::string matrix_text;      // transform: a pose as verify --pose takes it
  bool grid_normals = false;    // normals: from the scan grid
  bool hough = false;           // planes: Hough instead of RANSAC
  double voxel_m = 0.05;        // voxel: cube side
  double max_angle_deg = 10.0;  // regions: largest normal angle between neighbours
  int64_t count = 100000;       // sample: points to keep; sample-mesh: points to draw
};

// All scans of all inputs as one world-frame cloud, with where each point came from.
struct Gathered {
  std::vector<std::string> paths;  // the input files
  std::vector<Scan> scans;
  PointCloud cloud;
  std::vector<int32_t> scan_of_point;
  std::vector<int64_t> cell_of_point;
};

// What an operation writes: scans (their grids kept), a plain cloud, or a triangle mesh (each as .ply but scans).
enum class PointsOutputKind { kScans, kCloud, kMesh };

// What `lidarshop points OPERATION --json` reports (docs/points.md): one described struct per kind of
// operation, each holding its keys in the order the command has always written them. The inputs come first
// (PointsRead, written flat), `seconds` is the operation alone, without reading and writing.
struct PointsRead {
  std::string operation;
  int64_t input_points = 0;  // points of every input scan
  uint64_t scans = 0;        // input scans
  double read_seconds = 0;   // wall seconds reading them
};

// outliers, sample, crop: the points kept.
struct PointsKeptReport {
  PointsRead read;
  int64_t output_points = 0;
  double seconds = 0;
};

// voxel, merge: the plain cloud written.
struct PointsCloudReport {
  PointsRead read;
  double seconds = 0;
  uint64_t output_points = 0;
};

// transform, normals: the scans written, with their grids.
struct PointsScansReport {
  PointsRead read;
  double seconds = 0;
};

// A plane found by planes (pointset/planes.h PlaneFit without its inliers' indices).
struct PointsPlane {
  std::vector<double> normal;  // unit normal, world frame
  double offset_m = 0;         // plane: normal · x + offset_m = 0
  uint64_t inliers = 0;        // points within the distance threshold
  double rms_m = 0;            // RMS distance of the inliers to the plane
};

struct PointsPlanesReport {
  PointsRead read;
  std::vector<PointsPlane> planes;  // labels 0, 1, ... in the scans
  double seconds = 0;
};

struct PointsClusterReport {
  PointsRead read;
  int clusters = 0;
  std::vector<int64_t> cluster_sizes;  // points per cluster, largest first
  double seconds = 0;
};

struct PointsKMeansReport {
  PointsRead read;
  double inertia_m2 = 0;  // square metres, sum of squared distances to the assigned centres
  int iterations = 0;
  double seconds = 0;
};

struct PointsMeshReport {
  PointsRead read;
  std::string method;                  // grid, poisson or scale-space
  std::optional<std::string> normals;  // poisson: "estimated" or "input"
  double seconds = 0;
  uint64_t vertices = 0, triangles = 0;
};

// regions, superpixels: labels over every scan's grid.
struct PointsRegionsReport {
  PointsRead read;
  int regions = 0;
  double seconds = 0;
};

struct PointsSuperpixelsReport {
  PointsRead read;
  int superpixels = 0;
  double seconds = 0;
};

// sample-mesh: points drawn from a triangle mesh (no scans read).
struct PointsSampleMeshReport {
  std::string operation;
  uint64_t triangles = 0;      // of the input mesh
  uint64_t output_points = 0;  // drawn
  double seconds = 0;
};

struct PointsOutput {
  std::vector<Scan> scans;
  PointCloud cloud;
  TriangleMesh mesh;
  nlohmann::ordered_json report;  // ToJson of the operation's report (the --json without "options")
  std::string summary_line;  // what it kept or found, of how many points ("voxel: 120 input points, ...")
};

struct PointsOperation {
  std::string name;
  PointsOutputKind writes = PointsOutputKind::kScans;
  bool reads_mesh = false;           // its one input is a triangle mesh (sample-mesh), not scans
  std::vector<std::string> options;  // the PointsOptions members it uses, as in --json's "options"
  // Runs the operation on the gathered inputs (read as `read` says; or, when reads_mesh, on `mesh`), and
  // returns what to write with its report, whose seconds are `timer`'s when it is done. Throws OptionsError
  // for flags it cannot use, InputError for data.
  std::function<PointsOutput(const Gathered& inputs, const TriangleMesh& mesh, PointsOptions& options,
                             const PointsFlags& flags, const PointsRead& read, const Timer& timer)>
      run;
};

// Every operation, in the order the help lists them.
const std::vector<PointsOperation>& PointsOperations();

// The operation of that name; throws OptionsError listing every name when there is none.
const PointsOperation& FindPointsOperation(const std::string& name);

// "outliers | voxel | ..." for the help text.
std::string PointsOperationNames(const std::string& separator);

// The scans of `paths` gathered into one world-frame cloud; throws InputError when they hold no point.
Gathered GatherScans(const std::vector<std::string>& paths);

}  // namespace lidarshop::cli

namespace lidarshop {
// points_operations.cc
template <>
const StructInfo& InfoOf<cli::PointsRead>();
template <>
const StructInfo& InfoOf<cli::PointsKeptReport>();
template <>
const StructInfo& InfoOf<cli::PointsCloudReport>();
template <>
const StructInfo& InfoOf<cli::PointsScansReport>();
template <>
const StructInfo& InfoOf<cli::PointsPlane>();
template <>
const StructInfo& InfoOf<cli::PointsPlanesReport>();
template <>
const StructInfo& InfoOf<cli::PointsClusterReport>();
template <>
const StructInfo& InfoOf<cli::PointsKMeansReport>();
template <>
const StructInfo& InfoOf<cli::PointsMeshReport>();
template <>
const StructInfo& InfoOf<cli::PointsRegionsReport>();
template <>
const StructInfo& InfoOf<cli::PointsSuperpixelsReport>();
template <>
const StructInfo& InfoOf<cli::PointsSampleMeshReport>();
}  // namespace lidarshop
