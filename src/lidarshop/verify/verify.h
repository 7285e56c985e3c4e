// Verification of a hypothesized object pose against one or many registered scans: consistency, confidence
// and the trimmed-ICP baseline (thesis chapter 4, eqs. 4.1–4.6).
//
// An object detector or a registration proposes "model M is here, in pose world_from_model". Two measures in
// [0, 1] answer, independently of the method that produced the pose:
//
//  * Consistency (eqs. 4.1–4.3) — does the pose make physical sense? For every scene point j whose scanner
//    ray meets the posed model, d_m = distance along the ray to the model's first hit, d_s = measured range,
//    a = allowance:
//        consistent_j = [(d_m + a) − d_s ≥ 0]            (the point lies in front of the model or on it)
//        consistency  = Σ_scans Σ_j consistent_j / Σ_scans #comparable pairs
//    A ray that returned from *behind* the model went through it: the model cannot be there. Rays without a
//    return are not comparable (nothing was measured). With no comparable pair at all, consistency is NaN and
//    `has_comparable_pairs` is false — never a silent 1.
//
//  * Confidence (eqs. 4.4–4.5) — how much of the model has been seen? Model point i carries information I_i
//    (Σ I_i = 1; uniform 1/N, or weighted by shape distinctiveness), observed information O_i starts at 0,
//    and every scene point j within 3σ of model point i (the points of all scans accumulate) updates it:
//        O_i ← min(I_i, O_i + I_i · exp(−d_ij² / 2σ²)),      confidence = Σ_i O_i.
//    The update only adds and clamps, so O_i = I_i · min(1, Σ_j exp(−d_ij²/2σ²)), in any order of the points.
//
//  * Trimmed ICP cost (eq. 4.6, the baseline): mean distance from the scene points near the posed model
//    (inside its bounding box grown by the trim distance) to their nearest model point, pairs beyond
//    `icp_trim_m` excluded; the inlier fraction is the share of those scene points whose nearest model point
//    is within the trim distance.
//
// Speed (build once, query many; libigl-style precompute/query split):
//
//   VerifierModel model = PrepareModel(mesh_in_model, model_options);  // Embree scene + point grids
//   std::vector<PreparedScan> scans = {PrepareScan(scan_a), PrepareScan(scan_b)};
//   VerifyResult result = VerifyPose(model, scans, world_from_model, options);
//
// Per pose and scan, only the cells inside the model's angular footprint (its bounding box projected to
// azimuth / elevation → a column set and a row window of the organized grid) are visited, in bands of 4
// rows so that consecutive cells are neighbours. Their rays are moved into the MODEL frame and tested
// against the model scene built once in its own frame (two any-hit queries per ray, 16-ray packets), and
// their points are looked up in the model-point cell grids built once (KernelNeighbourGrid), grouped by
// cell, 8 model points per AVX2 instruction. Nothing is rebuilt per pose. VerifyPoses runs poses in
// parallel. bench/results/verify.md has the numbers.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

class Progress;

// How the model points of the confidence measure are chosen.
enum class ModelPointSource {
  kSurfaceSamples,  // uniform over the surface area (default: independent of the triangulation)
  kVertices,        // the mesh's vertices (the original work; biased towards finely triangulated parts)
};

// How the information I_i of the model points is distributed (it always sums to 1).
template <>
const EnumInfo& EnumInfoOf<ModelPointSource>();  // "surface-samples", "vertices"

enum class InformationWeighting {
  kUniform,               // I_i = 1/N
  kShapeDistinctiveness,  // I_i ∝ floor + surface variation (pointset/sampling.h) within
                          // distinctiveness_radius_m
};
template <>
const EnumInfo& EnumInfoOf<InformationWeighting>();  // "uniform", "shape-distinctiveness"

struct ModelOptions {
  // Metres per unit of the mesh: PrepareModel scales the mesh by it before anything else, so that the model
  // frame is in metres (0.001 for a mesh in millimetres, 0.0254 for inches). Equivalent to a uniform scale in
  // world_from_model (same numbers), but faster: the neighbour grids are built for σ and the trim in metres.
  double model_scale = 1.0;
  ModelPointSource point_source = ModelPointSource::kSurfaceSamples;
  static constexpr int64_t kMaxSurfaceSamples = int64_t{1} << 27;
  int64_t num_surface_samples =
      10000;          // count; for kSurfaceSamples. ≈ 5 cm apart on a car (25 m²): keep the spacing ≲ σ
  uint64_t seed = 1;  // seed of the surface sampling
  InformationWeighting information = InformationWeighting::kUniform;
  double distinctiveness_radius_m =
      0.0;  // metres; neighbourhood of the surface variation; 0 = 3% of the bbox diagonal
  double distinctiveness_floor = 0.02;  // unitless, added to every point's variation (flat parts still count)

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<ModelOptions>();

// Positions as three coordinate arrays (structure of arrays, for SIMD loads).
struct PointColumns {
  std::vector<float> x, y, z;
  void Assign(std::span<const Eigen::Vector3f> points);
  size_t size() const { return x.size(); }
};

// The model points sorted into cubic cells of edge ≥ `radius_m` (· 1.001, so that float rounding never puts
// a point within the radius two cells away): every model point within radius_m of a query lies in the
// 3 x 3 x 3 cells around the query's own, i.e. in nine contiguous runs of the sorted arrays. The points (12
// bytes each, ~120 KB for 10,000) stay in the L2 cache, which per-voxel candidate lists (tens of MB) did not.
struct PointCellGrid {
  float radius_m = 0.0f;                                      // the query radius it serves; 0 = not built
  Eigen::Vector3f origin_in_model = Eigen::Vector3f::Zero();  // corner of cell (0, 0, 0)
  float cell_m = 0.0f;                                        // edge of a cell, metres
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();             // cells along x, y, z
  std::vector<uint32_t> offsets;  // #cells + 1, CSR (cell = (z * dims.y + y) * dims.x + x)
  std::vector<uint32_t> indices;  // model point indices sorted by cell (ascending within a cell)
  PointColumns positions;         // their positions, same order
};

// Neighbour lookups of the model points without a tree descent (the hot loops of confidence and of the
// trimmed ICP), built once by PrepareModel for VerifyOptions::sigma_m and icp_trim_m; VerifyPose falls back
// to the KD-tree for other values (same results, slower). Both grids cover the model's box grown by
// max(3σ, trim); a query scans its 3 x 3 x 3 cells, 8 points per AVX2 instruction.
struct KernelNeighbourGrid {
  PointCellGrid kernel;  // radius 3σ: the confidence kernel's neighbours (and the ICP nearest when closer)
  PointCellGrid icp;     // radius = the ICP trim distance: the nearest model point when within it
  bool built() const { return kernel.radius_m > 0; }
};

// The model side, built once (model frame = the mesh's own coordinates times ModelOptions::model_scale).
struct VerifierModel {
  TriangleMesh mesh_in_model;
  RaycastScene scene_in_model;          // Embree scene of mesh_in_model, committed
  Eigen::AlignedBox3f bounds_in_model;  // of the vertices
  PointKdTree points_in_model;          // #N model points (the confidence measure's i), KD-tree built once
  std::vector<float> information;       // #N I_i, Σ = 1
  KernelNeighbourGrid kernel_grid;      // for the σ given to PrepareModel
  double surface_area_m2 = 0.0;
  size_t num_points() const { return information.size(); }
};

struct VerifyOptions;

// Throws InputError for an empty mesh or one with no surface area. `verify_options.sigma_m` is the σ the
// kernel grid is built for (VerifyPose with another σ is still exact, only slower).
VerifierModel PrepareModel(const TriangleMesh& mesh_in_model, const ModelOptions& options,
                           const VerifyOptions& verify_options);
VerifierModel PrepareModel(const TriangleMesh& mesh_in_model, const ModelOptions& options = {});

// The scene side, built once per scan: the scan (buffers shared, not copied), its pose, and its angular grid
// (one azimuth per column, one elevation per image row) used to find a model's footprint.
struct PreparedScan {
  Scan scan;
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d scanner_from_world = Eigen::Matrix4d::Identity();
  std::vector<double> column_azimuth_rad;  // #cols, from scan.grid when it matches, else from the directions
  std::vector<double> row_elevation_rad;   // #rows
  double azimuth_step_rad = 0.0;  // largest step between neighbouring columns / rows (footprint margin)
  double elevation_step_rad = 0.0;
  int64_t num_valid = 0;
  // The cells again as (x, y, z, range) in the scanner frame, range 0 without a return, in the order the
  // footprint is walked: bands of kBandRows image rows, column after column within a band, top row first.
  // One sequential 16-byte read per cell instead of three arrays (and 4 rows' pointers) per cell.
  static constexpr int kBandRows = 4;
  std::vector<Eigen::Vector4f> band_cells;  // #ceil(rows / kBandRows) * kBandRows * cols
  size_t BandCellIndex(int row, int col) const {
    return (static_cast<size_t>(row / kBandRows) * scan.cols + col) * kBandRows + row % kBandRows;
  }
};

// Throws InputError when the scan has no cells or no usable directions.
PreparedScan PrepareScan(const Scan& scan);

struct VerifyOptions {
  double allowance_m = 0.10;  // a, metres (eq. 4.1). ≈ 2–3× range noise + model inaccuracy; 0.02 for a 30 cm
                              // sculpture, 0.10 for cars
  double sigma_m =
      0.05;  // σ, metres (eq. 4.4). ≈ scan point spacing on the object; 0.005 for a 30 cm sculpture
  double icp_trim_m = 0.20;             // metres: ICP pairs beyond this are excluded (eq. 4.6)
  double footprint_margin_cells = 1.0;  // cells added around the model's angular footprint (noise, rounding)
  bool keep_details = false;  // fill VerifyResult::scene_status and ::observed_information (for PLY output)

  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<VerifyOptions>();

// The outcome for one scan alone (consistency and confidence as if it were the only scan).
struct ScanVerifyStats {
  std::string scan;              // the scan's name (Scan::name)
  int64_t comparable_pairs = 0;  // valid points whose ray meets the posed model
  int64_t consistent_pairs = 0;  // of those, (d_m + a) − d_s ≥ 0
  double consistency = std::numeric_limits<double>::quiet_NaN();  // NaN when comparable_pairs == 0
  double confidence = 0.0;                                        // from this scan's points only
  int64_t footprint_cells = 0;                                    // cells of the angular footprint visited
  int64_t rays_cast = 0;  // rays cast against the model (valid cells whose ray meets its bounding box)
};

// Status of a scene point in VerifyResult::scene_status.
enum SceneStatus : uint8_t { kNotComparable = 0, kConsistent = 1, kInconsistent = 2 };

struct VerifyResult {
  double consistency = std::numeric_limits<double>::quiet_NaN();  // [0, 1]; NaN when no comparable pair
  bool has_comparable_pairs = false;
  int64_t comparable_pairs = 0;
  int64_t consistent_pairs = 0;
  double confidence = 0.0;  // [0, 1], Σ O_i over the points of all scans
  double icp_cost_m = std::numeric_limits<double>::quiet_NaN();  // NaN when no inlier pair
  double inlier_fraction = 0.0;  // inliers / scene points near the model (0 when none near)
  int64_t icp_inliers = 0;
  int64_t icp_candidates = 0;  // scene points inside the model's bounding box grown by icp_trim_m
  std::vector<ScanVerifyStats> per_scan;

  // With VerifyOptions::keep_details:
  std::vector<cv::Mat> scene_status;        // per scan, CV_8U rows x cols of SceneStatus
  std::vector<float> observed_information;  // #N O_i (all scans)

  // One line: "consistency 0.98 (1234 pairs), confidence 0.41, icp 0.012 m (inliers 0.93)".
  std::string BriefReport() const;
};
template <>
const StructInfo& InfoOf<VerifyResult>();
template <>
const StructInfo& InfoOf<ScanVerifyStats>();

// What `lidarshop verify --json` reports: the pose's VerifyResult (its keys at the report's own level), each
// scan's numbers, the pose verified and the model's.
struct VerifyReport {
  VerifyResult result;                                         // written flat: consistency ... icp_candidates
  double icp_cost = std::numeric_limits<double>::quiet_NaN();  // metres, = result.icp_cost_m (older key)
  std::vector<ScanVerifyStats> per_scan;                       // = result.per_scan, by scan
  // The pose verified, rounded as reported (geometry/transform.h RoundedPose).
  Eigen::Matrix4d world_from_model = Eigen::Matrix4d::Identity();
  int64_t model_points = 0;    // VerifierModel::num_points()
  ModelOptions model_options;  // how the model points were made
};
template <>
const StructInfo& InfoOf<VerifyReport>();

// The report of `result`, the pose `world_from_model` verified against `model` made with `model_options`.
VerifyReport MakeVerifyReport(const VerifyResult& result, const VerifierModel& model,
                              const ModelOptions& model_options, const Eigen::Matrix4d& world_from_model);

// Verifies one pose. `world_from_model` is a rotation times one uniform scale s plus a translation
// (geometry/transform.h PoseProblem; std::invalid_argument otherwise). Every distance of the measures stays
// in world metres whatever s is: the allowance along the rays, σ and the trim distance (divided by s in the
// model frame) and the ICP cost (multiplied back). A scale in the pose and the mesh pre-scaled by s
// (ModelOptions::model_scale) give the same numbers; with s ≠ 1 the kernel grid built for σ does not apply
// and the KD-tree answers (same results, slower).

VerifyResult VerifyPose(const VerifierModel& model, std::span<const PreparedScan> scans,
                        const Eigen::Matrix4d& world_from_model, const VerifyOptions& options = {});

// Verifies many poses in parallel (each pose single-threaded; results do not depend on the thread count).
std::vector<VerifyResult> VerifyPoses(const VerifierModel& model, std::span<const PreparedScan> scans,
                                      std::span<const Eigen::Matrix4d> world_from_model,
                                      const VerifyOptions& options = {}, Progress* progress = nullptr);

// The scene points of every scan in the world frame, coloured by status (green consistent, red inconsistent,
// grey not comparable); needs a result computed with keep_details.
PointCloud SceneStatusCloud(std::span<const PreparedScan> scans, const VerifyResult& result);
// The model points in the world frame coloured by O_i / I_i (red unseen → green seen); needs keep_details.
PointCloud ObservedModelCloud(const VerifierModel& model, const Eigen::Matrix4d& world_from_model,
                              const VerifyResult& result);

// world_from_model of an object standing on the ground: rotation R = Rz(yaw) · Ry(pitch) · Rx(roll) (degrees;
// roll about x first, then pitch about y, then yaw about z; yaw turns +x towards +y), then translation by
// (x, y, z) metres. R is geometry/transform.h's RotationFromEulerDegrees({roll, pitch, yaw}), the convention
// of scene files and every other place that takes angles.
Eigen::Matrix4d PoseFromXyzYaw(double x_m, double y_m, double z_m, double yaw_deg, double pitch_deg = 0.0,
                               double roll_deg = 0.0);

}  // namespace lidarshop
