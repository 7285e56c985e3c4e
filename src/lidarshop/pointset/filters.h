// Cleaning and thinning of point sets (thesis table 3.1): outlier removal, subsampling, crops, transforms and
// merges, over plain point clouds and over organized scans.
//
// Filters that only drop points return keep flags (#P, 1 = keep) so that the same answer can thin a
// PointCloud (SelectPoints) or an organized scan without losing its grid (KeepScanCells: dropped cells become
// cells without a return). Subsampling that creates new points (voxel centroids) works on clouds only.
//
//   const std::vector<uint8_t> keep = StatisticalOutlierInliers(cloud, {.neighbors = 20, .std_ratio = 2.0});
//   PointCloud clean = SelectPoints(cloud, keep);
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// Throws InputError naming `what` when the cloud is empty or every point is the same (no shape to work on).
void CheckCloudHasShape(const PointCloud& cloud, std::string_view what);
// Throws InputError naming `what` when the cloud has fewer than `count` points.
void CheckCloudHasPoints(const PointCloud& cloud, int64_t count, std::string_view what);

// Statistical outlier removal (PCL's StatisticalOutlierRemoval, Open3D's remove_statistical_outlier): the
// mean distance of each point to its `neighbors` nearest others; points whose mean is above μ + std_ratio · σ
// of all means are outliers.
struct StatisticalOutlierOptions {
  int neighbors = 20;      // k nearest neighbours (the point itself not counted), >= 1, < #P
  double std_ratio = 2.0;  // threshold in standard deviations of the mean distances, > 0
  void Check() const;      // throws OptionsError
};
template <>
const StructInfo& InfoOf<StatisticalOutlierOptions>();
std::vector<uint8_t> StatisticalOutlierInliers(const PointCloud& cloud,
                                               const StatisticalOutlierOptions& options);

// Radius outlier removal: a point is kept when at least `min_neighbors` other points lie within `radius_m`.
struct RadiusOutlierOptions {
  double radius_m = 0.05;  // metres, > 0
  int min_neighbors = 2;   // other points needed within the radius, >= 1
  void Check() const;      // throws OptionsError
};
template <>
const StructInfo& InfoOf<RadiusOutlierOptions>();
std::vector<uint8_t> RadiusOutlierInliers(const PointCloud& cloud, const RadiusOutlierOptions& options);

// Crop: a point is kept when it passes every test that is set (AND); `invert` keeps the others instead.
struct CropOptions {
  std::optional<Eigen::AlignedBox3f> box;  // keep points inside this box, metres, the cloud's frame
  std::vector<Eigen::Vector2f> polygon;    // keep points whose (x, y) lies inside this polygon (>= 3 corners)
  std::vector<int32_t> labels;             // keep points with one of these labels (needs labels)
  double min_range_m = 0.0;                // keep points at least this far from `origin`, metres
  double max_range_m = 0.0;                // and at most this far (0 = no upper bound)
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();  // where ranges are measured from (the scanner)
  double min_intensity = 0.0;                        // keep intensities in [min, max] (needs intensities
  double max_intensity = 1.0;                        // when the interval is narrower than [0, 1])
  bool invert = false;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<CropOptions>();
// Throws InputError when a test needs an attribute the cloud lacks.
std::vector<uint8_t> CropInliers(const PointCloud& cloud, const CropOptions& options);

// The points (and every attribute) whose flag is non-zero, in their order.
PointCloud SelectPoints(const PointCloud& cloud, const std::vector<uint8_t>& keep);

// Organized scans: `keep` is per point of ToPointCloud(scan, world, &cell_index); the scan keeps its grid,
// dropped cells become cells without a return (MaskScan).
Scan KeepScanCells(const Scan& scan, const std::vector<int64_t>& cell_index,
                   const std::vector<uint8_t>& keep);

// Voxel grid subsampling: one point per occupied cube of side `voxel_m` (metres, > 0), at the centroid of its
// points; normals (renormalized), colours and intensities are averaged, labels and synthesized come from the
// voxel's first point. Points come out in the order of each voxel's first point.
PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_m);

// `count` points chosen uniformly without replacement (all of them when count >= #P), kept in their order.
// The same cloud, count and seed give the same choice on every machine.
std::vector<uint8_t> RandomSampleInliers(const PointCloud& cloud, int64_t count, uint64_t seed);

// A scan moved rigidly: world_from_scanner becomes b_from_world · world_from_scanner (the points stay in the
// scanner frame). Throws OptionsError when `b_from_world` is not rigid.
Scan TransformScan(const Scan& scan, const Eigen::Matrix4d& b_from_world);

// All clouds in one; an attribute is kept only when every cloud has it. Throws
// InputError when none has points.
PointCloud MergeClouds(const std::vector<PointCloud>& clouds);

}  // namespace lidarshop
