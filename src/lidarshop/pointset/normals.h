// Normals and curvature of point sets by principal component analysis of a neighbourhood (Hoppe et al. 1992;
// PCL's NormalEstimation, Open3D's estimate_normals): the normal is the eigenvector of the smallest
// eigenvalue of the neighbours' covariance, oriented toward the scanner; the curvature is the surface
// variation λ0 / (λ0 + λ1 + λ2) (Pauly et al. 2002), 0 on a plane, up to 1/3.
//
// Three neighbourhoods: the k nearest points, all points within a radius (KD-tree), or on an organized scan
// the cells of a square window of the grid whose points lie within a radius (no tree, the grid is the index).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct NormalOptions {
  int neighbors = 20;      // k nearest points (the point itself included), >= 3; used when radius_m == 0
  double radius_m = 0.0;   // > 0: all points within this radius instead of the k nearest (metres)
  int max_neighbors = 64;  // radius mode: at most this many nearest points within the radius (0 = all)
  int window_cells = 2;    // grid mode: half-width of the window of cells, >= 1
  // Orientation: normals point toward this point (the scanner origin, in the cloud's frame).
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<NormalOptions>();

struct NormalResult {
  std::vector<Eigen::Vector3f> normals;  // #P unit normals toward the viewpoint; 0 where < 3 neighbours
  std::vector<float> curvature;          // #P surface variation in [0, 1/3]; 1/3 where < 3 neighbours
};

// Throws InputError on an empty cloud, identical points, or k larger than the cloud.
NormalResult EstimateNormals(const PointCloud& cloud, const NormalOptions& options);

// Organized scans: normals from the grid (`window_cells`, and when radius_m > 0 only cells whose point lies
// within radius_m of the centre), in the scanner frame, toward the scanner origin. `normal` CV_32FC3 and
// `curvature` CV_32F, rows x cols, 0 (normal) / NaN (curvature) where the cell has no return or too few
// neighbours. `viewpoint` is ignored (the scanner origin is the viewpoint).
struct GridNormalResult {
  cv::Mat normal;
  cv::Mat curvature;
};
GridNormalResult EstimateGridNormals(const Scan& scan, const NormalOptions& options);
// One cell's grid normal and curvature as EstimateGridNormals computes it (the same numbers), for callers that
// need a few cells of a large scan; false (outputs untouched) where EstimateGridNormals leaves 0 / NaN.
// `options` is not checked here.
bool GridNormalAt(const Scan& scan, const NormalOptions& options, int row, int col, cv::Vec3f* normal,
                  float* curvature);

// The scan with its `normal` and `curvature` channels replaced by the grid normals and their curvature.
Scan WithGridNormals(const Scan& scan, const NormalOptions& options);

}  // namespace lidarshop
