// Rigid registration of two point sets: point-to-plane ICP from an initial guess (Chen and Medioni 1992;
// Open3D's registration_icp with TransformationEstimationPointToPlane), and a global initial alignment from
// FPFH features (Rusu et al. 2009) matched by RANSAC when there is no guess.
//
// Frames: `fixed` stays where it is; the result maps moving coordinates into the fixed cloud's frame
// (`fixed_from_moving`). For scans both clouds are taken in the world frame and the correction is applied to
// the moving scan's world_from_scanner (RegisterScans).
#pragma once

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/pointset/features.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct IcpOptions {
  double max_correspondence_m = 0.2;  // pairs farther apart are ignored at first, metres, > 0
  // The pairing distance then shrinks to 3x the point-to-point RMS of the last pairs, but not below this
  // (metres, > 0): far pairs at occlusion edges are wrong pairs and bias the pose.
  double min_correspondence_m = 0.02;
  // When both clouds have normals, pairs whose normals differ by more than acos(this) are ignored ([-1, 1]).
  double min_normal_cos = 0.7;
  int max_iterations = 50;          // >= 1
  double min_translation_m = 1e-5;  // converged when an update moves less than this (metres)
  double min_rotation_rad = 1e-6;   // and turns less than this (radians), >= 0
  int normal_neighbors = 20;        // k for the fixed cloud's normals when it has none, >= 3
  void Check() const;               // throws OptionsError
};
template <>
const StructInfo& InfoOf<IcpOptions>();

struct IcpResult {
  Eigen::Matrix4d fixed_from_moving = Eigen::Matrix4d::Identity();
  double rms_m = 0.0;    // point-to-plane RMS of the last correspondences, metres
  double fitness = 0.0;  // fraction of moving points with a correspondence at the end
  int64_t correspondences = 0;
  int iterations = 0;
  bool converged = false;
};
// Described: its numbers (rms_m ... converged). fixed_from_moving is not: a result holding an IcpResult
// reports the pose its caller knows (SitePair's a_from_b, ScanRegistrationSummary's world_from_scanner).
template <>
const StructInfo& InfoOf<IcpResult>();

// Point-to-plane ICP. Uses fixed.normals when present (else estimates them). Throws InputError on empty or
// degenerate clouds and when no correspondence is found within max_correspondence_m from the initial guess.
IcpResult IcpPointToPlane(const PointCloud& fixed, const PointCloud& moving,
                          const Eigen::Matrix4d& initial_fixed_from_moving, const IcpOptions& options);

// Registers `moving` onto `fixed` (both in their world frames, moving's world_from_scanner as the initial
// guess, or with `global` a FPFH + RANSAC alignment first) and returns the moving scan with
// world_from_scanner corrected.
struct ScanRegistration {
  Scan registered;  // the moving scan, new world_from_scanner
  IcpResult icp;    // fixed_from_moving = the correction applied in world coordinates
};
ScanRegistration RegisterScans(const Scan& fixed, const Scan& moving, const IcpOptions& options,
                               const GlobalAlignOptions* global = nullptr);

// What `lidarshop register FIXED MOVING --json` reports: the moving scan's registered pose and its ICP's
// numbers.
struct ScanRegistrationSummary {
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();  // the moving scan's, registered
  double rms_m = 0.0;                                                // IcpResult::rms_m, metres
  double fitness = 0.0;                                              // IcpResult::fitness, [0, 1]
  int iterations = 0;                                                // IcpResult::iterations
  bool converged = false;                                            // IcpResult::converged
  double seconds = 0.0;                              // the caller's: reading the scans and registering them
  std::optional<GlobalAlignOptions> global_options;  // the global alignment's options, when it ran first
};
template <>
const StructInfo& InfoOf<ScanRegistrationSummary>();

// The summary of `registration`, made by RegisterScans with `global` (nullptr: no global alignment); seconds
// is left 0.
ScanRegistrationSummary SummarizeScanRegistration(const ScanRegistration& registration,
                                                  const GlobalAlignOptions* global = nullptr);

}  // namespace lidarshop
