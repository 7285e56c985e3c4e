// Resectioning: the camera that took a photo, from 2-D/3-D correspondences (thesis 3.2.2).
//
//   1. Normalized DLT (thesis eqs. 3.1–3.6; Hartley & Zisserman alg. 7.1): pixels moved to zero mean and mean
//      distance √2, points to zero mean and mean distance √3; the 2N x 12 system A p = 0 solved by the SVD
//      (the right singular vector of the smallest singular value), then denormalized.
//   2. RANSAC over minimal sets of 6 pairs (seeded: same result on any thread count; the loop is serial),
//      inliers = pairs whose DLT reprojection error is below `ransac_threshold_px`. Locally optimized
//      (LO-RANSAC, Chum et al. 2003): each set with at least as many inliers as the best so far (each
//      distinct inlier set once) is refitted on its inliers (DLT, then step 4, inliers re-selected) and the sets are
//      compared by the MSAC score of the refined camera. A minimal DLT on 6 noisy pairs is unstable, and with
//      few pairs a wrong set (an outlier among them) can collect as many pairs as the right one; refined, it
//      explains them worse. A set whose DLT is no plausible camera (far from square pixels and zero
//      skew: an outlier among the 6, or points near one plane, which leave the DLT's intrinsics undetermined)
//      is skipped without local optimization; with it, the set gets the camera of the intrinsics prior
//      (square pixels, principal point at the centre: EPnP for a few fields of view, then LM over f and
//      the pose). At least `ransac_min_iterations` sets, then the adaptive bound. A set is also locally
//      optimized when its MSAC score beats the best's (a camera bent to absorb an outlier keeps one pair more
//      than the right one, loosely). Then a swap search: each inlier traded for each of the (at most 3)
//      nearest pairs just outside the threshold, refitted, the lowest MSAC score kept, until none lowers it
//      (an outlier fitted exactly can push a right pair out: as many inliers, as tight).
//   3. P = K [R | t] decomposed by an RQ decomposition (K upper triangular, positive diagonal; R a rotation).
//   4. Levenberg–Marquardt on the reprojection error of the inliers over focal length(s), principal point,
//      optionally skew, radial (k1, k2, k3) and tangential (p1, p2) distortion, rotation (angle-axis) and
//      translation; inliers are then re-selected with the refined camera and the refinement repeated once.
//      The intrinsics freed follow the inlier count: below `min_inliers_for_principal_point` the principal
//      point stays at the photo's centre (and skew at 0), below `min_inliers_for_distortion` no distortion.
//      The solver is Eigen's unsupported LevenbergMarquardt (MINPACK lmdif) with forward-difference
//      Jacobians: a 16-parameter problem with at most a few hundred residuals needs no sparse solver, and it
//      keeps lidarshop free of a new dependency (Ceres is not in the base image) while letting us free or
//      fix any subset of the intrinsics, which OpenCV's solvePnPRefineLM (fixed intrinsics) cannot.
//
// Degenerate input is refused with an InputError naming the reason: fewer than 6 pairs, non-finite values,
// collinear pixels, or all points on one plane (or a line) — a plane does not determine the intrinsics;
// give them (`ResectWithIntrinsics`) for planar targets.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// One correspondence: a photo pixel (continuous coordinates, geometry/camera.h)
// and the world point seen there.
struct PixelPointPair {
  Eigen::Vector2d pixel_px = Eigen::Vector2d::Zero();
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
};

struct ResectionOptions {
  int width_px = 0, height_px = 0;   // the photo's size (stored in the camera); required, > 0
  double ransac_threshold_px = 4.0;  // a pair is an inlier when its reprojection error is below this, pixels
  int ransac_iterations = 2000;      // most minimal sets tried (fewer when the confidence is reached)
  int ransac_min_iterations = 100;   // fewest minimal sets tried, whatever the adaptive bound says
  // LO-RANSAC: a minimal set with at least as many inliers as the best set (or a lower MSAC score) is
  // refitted on them (DLT, then Levenberg–Marquardt with the intrinsics the count supports, inliers
  // re-selected) and scored (MSAC) after that refinement: a wrong set that happens to collect many pairs loses
  // to the right one. Also turns on the swap search after RANSAC (needs `refine`).
  bool local_optimization = true;
  double ransac_confidence = 0.9999;  // stop once a better set is this unlikely
  uint64_t seed = 1;                  // RANSAC's random sets
  bool refine = true;                 // false = the (RANSAC) DLT camera without Levenberg–Marquardt
  bool square_pixels = true;          // refine one focal length (fx = fy)
  // With square_pixels, RANSAC skips minimal-set cameras with |fx / fy − 1| or |skew| / fx above this (a set
  // of 6 pairs fits almost any camera; an implausible one comes from outliers). Inliers must also lie in
  // front of the camera.
  double max_aspect_deviation = 0.2;
  bool refine_skew = false;  // false = skew 0
  // How many of k1, k2, k3 are refined (0–3). One by default: with 16-30 noisy pairs k2 fits the noise
  // (a synthetic test reached 3 px error away from the pairs with k1, k2 free).
  int radial_coefficients = 1;
  bool refine_tangential = false;  // refine p1, p2
  // Distortion is refined only with at least this many inliers (fewer pairs would fit the noise).
  int min_inliers_for_distortion = 16;
  // Below this many inliers the principal point stays at the photo's centre and the skew at 0 (only the focal
  // length and the pose are refined): with 8 inliers of 0.35 px noise a free principal point wandered 30 px
  // and doubled the error (bench/results/recolor.md).
  int min_inliers_for_principal_point = 12;
  // Points count as coplanar (or collinear) when the smallest spread of their centred coordinates is below
  // this fraction of the largest; same for collinear pixels.
  double degenerate_ratio = 1e-3;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<ResectionOptions>();

struct ResectionResult {
  PinholeCamera camera;                       // the final camera (refined unless options.refine is false)
  Eigen::Matrix<double, 3, 4> projection;     // P of the DLT on the RANSAC inliers, pixels (scale: |P| = 1)
  std::vector<double> reprojection_error_px;  // per pair (all pairs), with `camera`
  std::vector<uint8_t> inlier;                // per pair: 1 = inlier
  int num_inliers = 0;
  double rms_px = 0;      // RMS reprojection error of the inliers with `camera`
  double dlt_rms_px = 0;  // the same with the DLT camera (before refinement)
  int ransac_iterations = 0;
  // What looks wrong, one sentence each (an RMS above kResectionRmsWarningPx); empty if nothing.
  std::vector<std::string> warnings;
  std::string Summary() const;  // one line
};

// A camera whose inliers reproject with an RMS above this is reported, pixels: clicked pairs are good to a
// pixel or two; beyond a few pixels a pair is wrong or the model (distortion) does not fit, and a recolouring
// with it paints the edges of objects onto their neighbours.
inline constexpr double kResectionRmsWarningPx = 3.0;

// One pair's reprojection error with the final camera and whether RANSAC kept it. Described.
struct ResectionPairError {
  double error_px = 0;  // pixels
  bool inlier = false;
};
template <>
const StructInfo& InfoOf<ResectionPairError>();

// A resection in brief: the result of `lidarshop resection --json` (and recolor's "resection"), in its order.
// Described.
struct ResectionSummary {
  int inliers = 0;
  int64_t pairs = 0;  // pairs given (inliers and outliers)
  double rms_px = 0, dlt_rms_px = 0;
  int ransac_sets = 0;                       // ResectionResult::ransac_iterations
  std::vector<double> focal_px;              // fx, fy, pixels
  std::vector<double> principal_point_px;    // cx, cy, pixels
  double k1 = 0;                             // first radial distortion coefficient
  std::vector<double> camera_center;         // x, y, z in the world frame, metres
  std::vector<ResectionPairError> per_pair;  // one per pair, in the file's order
  std::vector<std::string> warnings;
  // The options it ran with, where a command nests the resection in its own result (recolor
  // --correspondences); empty elsewhere (the command's "options" hold them).
  std::optional<ResectionOptions> options;
};
ResectionSummary SummarizeResection(const ResectionResult& result);
template <>
const StructInfo& InfoOf<ResectionSummary>();

// Thesis eqs. 3.1–3.6 with normalization: P (3x4, |P| = 1) from at least 6 pairs. No degeneracy check.
Eigen::Matrix<double, 3, 4> NormalizedDlt(std::span<const PixelPointPair> pairs);

// P = K [R | t]: K upper triangular with K(2, 2) = 1 and positive diagonal, R a rotation (camera_from_world).
struct ProjectionFactors {
  Eigen::Matrix3d K;
  Eigen::Matrix3d camera_from_world_rotation;
  Eigen::Vector3d camera_from_world_translation;
};
ProjectionFactors DecomposeProjection(const Eigen::Matrix<double, 3, 4>& projection);
// The undistorted camera of a projection matrix.
PinholeCamera CameraFromProjection(const Eigen::Matrix<double, 3, 4>& projection, int width_px,
                                   int height_px);

// Reprojection error of one pair with a camera (infinity when the point is behind the camera), pixels.
double ReprojectionError(const PinholeCamera& camera, const PixelPointPair& pair);

// Throws InputError (naming `what`) when the pairs cannot determine a camera: < 6 pairs, non-finite values,
// collinear pixels, coplanar points (`points_may_be_planar` allows coplanar, non-collinear points).
void CheckResectionInput(std::span<const PixelPointPair> pairs, double degenerate_ratio,
                         const std::string& what, bool points_may_be_planar = false);

// Steps 1–4 above. `what` names the source of the pairs in errors.
ResectionResult Resection(std::span<const PixelPointPair> pairs, const ResectionOptions& options,
                          const std::string& what = "correspondences");

// Pose only, with known intrinsics (and distortion) in `intrinsics` (its pose is ignored): OpenCV's
// solvePnPRansac (EPnP minimal sets, seeded through cv::theRNG) then solvePnPRefineLM on the inliers. Works
// for planar targets; needs at least 4 pairs. The baseline of bench/results/recolor.md.
ResectionResult ResectWithIntrinsics(std::span<const PixelPointPair> pairs, const PinholeCamera& intrinsics,
                                     const ResectionOptions& options,
                                     const std::string& what = "correspondences");

}  // namespace lidarshop
