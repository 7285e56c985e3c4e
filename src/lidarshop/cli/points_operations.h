// The operations of `lidarshop points` as one table (docs/points.md): each names the PointsOptions members it
// uses, what it writes, and the function that runs it on the gathered inputs. The command parses, gathers,
// looks the operation up and writes what it returns; the help text, the "unknown operation" message and the
// options reported in --json all come from the table. CLI-internal.
#pragma once

#include <cstdint>
#include <functional>
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

struct PointsOutput {
  std::vector<Scan> scans;
  PointCloud cloud;
  TriangleMesh mesh;
};

struct PointsOperation {
  std::string name;
  PointsOutputKind writes = PointsOutputKind::kScans;
  bool reads_mesh = false;           // its one input is a triangle mesh (sample-mesh), not scans
  std::vector<std::string> options;  // the PointsOptions members it uses, as in --json's "options"
  // Runs the operation on the gathered inputs (or, when reads_mesh, on `mesh`), adds its results to
  // `summary`, and returns what to write. Throws OptionsError for flags it cannot use, InputError for data.
  std::function<PointsOutput(const Gathered& inputs, const TriangleMesh& mesh, PointsOptions& options,
                             const PointsFlags& flags, nlohmann::ordered_json* summary)>
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
