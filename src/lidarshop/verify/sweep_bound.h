// An upper bound on the confidence of a block of sweep poses (internal to the coarse-to-fine sweep).
//
// Why refining only the blocks that can still pass misses no detection. The poses of a block share one yaw
// θ and lie within `radius_m` of the block's centre c in x, y (poses PoseFromXyzYaw(x, y, z_m, θ): rotation
// about z, then translation). So for every pose P of the block, every model point i lies at
//     p_i(P) = p_i(C) + t,  |t| ≤ radius_m, t horizontal,
// where C is the pose at the centre: the same height, at most radius_m away horizontally. Confidence is
//     Σ_i I_i · min(1, Σ_j exp(−d_ij² / 2σ²)),  the inner sum over scene points j with d_ij < 3σ
// (verify.h, eq. 4.5; verify.cc only counts points within the kernel radius 3σ). A model point without a
// scene point within 3σ contributes 0, and no term exceeds I_i, so
//     confidence(P) ≤ Σ_i I_i · [∃ j: |q_j − p_i(P)| < 3σ]
//                  ≤ Σ_i I_i · [∃ j: |z_j − z_i| ≤ 3σ and |q_j,xy − p_i,xy(C)| ≤ 3σ + radius_m]     (*)
// by the triangle inequality, for every pose of the block at once, over the points of all scans together (a
// pose's own count sees only a subset of them, those in its footprint). (*) is this class's bound: a
// Lipschitz-style bound in the sense that it grows with the block's radius, and for a single pose (radius 0)
// it is the share of the model with any scene point within 3σ. If (*) ≤ t, no pose of the block can have
// confidence > t, so it can be neither a detection (confidence > min_confidence) nor a refinement seed
// (confidence > refine_min_confidence): skipping it changes neither the detections nor the refined poses.
//
// How (*) is evaluated cheaply and still from above: the scene points within the reach of any block are
// binned into columns of v × v metres (v ≈ σ) and slabs of σ/5; for each window of slabs (the slabs a model
// point's z ± 3σ can touch), the exact Euclidean distance transform (OpenCV, DIST_MASK_PRECISE) of the
// window's occupied columns gives, per column, the distance D (in cells, rounded down) to the nearest
// occupied column. Points in columns D apart
// are at least (D − √2) · v apart horizontally (each lies within v/√2 of its cell's centre); one more cell
// is allowed for rounding, and the radii get a margin of 1e-4 m plus 1e-4 relative (float poses in verify).
// So a model point is counted whenever a scene point *might* be close enough; the bound only gets looser.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::verify_internal {

class SweepConfidenceBound {
 public:
  // For blocks of `options`' grid whose radius is at most `max_radius_m`; `sigma_m` is the kernel's σ.
  SweepConfidenceBound(const VerifierModel& model, std::span<const PreparedScan> scans,
                       const SweepOptions& options, double sigma_m, double max_radius_m);

  // The bound (*) for the poses of yaw `yaw_deg` within `radius_m` of (x_m, y_m); stops counting once it
  // exceeds `stop_above` (the result is then > stop_above but not the full sum).
  double UpperBound(double x_m, double y_m, double yaw_deg, double radius_m, double stop_above) const;

  double cell_m() const { return cell_m_; }

 private:
  double cell_m_ = 0;                      // v: columns v x v
  double slab_m_ = 0;                      // slabs of this height
  double kernel_m_ = 0;                    // 3σ with its margin
  double x0_m_ = 0, y0_m_ = 0, z0_m_ = 0;  // corner of cell (0, 0, 0), world
  int nx_ = 0, ny_ = 0, nz_ = 0;
  // Per window start k used by a model point: the distance transform (CV_8U, ny × nx, whole cells, rounded
  // down, at most 255) of the columns holding scene points with z in slabs [k, k + window); empty when the
  // window holds no point or no model point uses it.
  std::vector<cv::Mat> window_distance_;
  // The model points (model frame) and their information, and each one's first slab (z fixed in a sweep).
  std::vector<Eigen::Vector3d> points_in_model_;
  std::vector<double> information_;
  std::vector<int> first_slab_;
  std::vector<const uint8_t*> window_of_point_;  // window_distance_[first_slab_[i]].data, or nullptr
  // Per yaw of the sweep: the model points' x, y rotated by it, in cells (the rest computed when asked).
  std::vector<double> yaws_deg_;
  std::vector<std::vector<Eigen::Vector2d>> rotated_cells_;
  std::vector<Eigen::Vector2d> RotatedCells(double yaw_deg) const;
};

}  // namespace lidarshop::verify_internal
