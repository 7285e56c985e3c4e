// The synthetic scanner: ground truth for every later algorithm.
//
// Casts the scanner's uniform azimuth x elevation grid (scanner/scene.h: ScannerOptions) into a scene of
// meshes and returns an organized Scan (scan/scan.h) in image orientation (row 0 = highest elevation, columns
// left to right) with every channel filled:
//   valid, range (noisy), point (noisy, scanner frame), intensity (ScannerOptions' model), color (material,
//   triangle colours or texture looked up at the hit point; procedural textures are band-limited to the ray's
//   footprint range · angular step / cos(incidence), so they do not alias at range: scanner/texture.h), label
//   (object label, kNoLabel where no return), normal (true surface normal, scanner frame, facing the scanner:
//   interpolated vertex normals where the mesh has them, else the geometric normal), true_range (noise-free
//   range), direction (every cell), world_from_scanner.
//
// Noise (per cell, from a counter-based hash of (seed, cell index), so identical whatever the thread count):
//   point = (true_range + e_los) · d + e_orth · (cos ψ · b1 + sin ψ · b2), e_los ~ N(0, σ_los²),
//   e_orth ~ N(0, σ_orth²), ψ ~ U[0, 2π), (b1, b2) an orthonormal basis perpendicular to the ray d
//   (b1 = (cos θ, -sin θ, 0), horizontal; b2 = d × b1).
//   range = |point|. A 32-bit hash (the "lowbias32" mixer) of the cell index row * cols + col, keyed by the
//   seed, gives two 16-bit uniforms, mapped to standard normals through a 65,536-entry quantile table
//   (inverse-CDF sampling, |e| <= 4.17 σ); a second hash of the first gives 10 bits for ψ.
//
// Speed: the scanner works through bands of 4 image rows per thread: directions, 4 x 4 packets of rays
// (rtcIntersect16), then shading 8 cells per SIMD step (scanner/shade.h), with an AVX2 path chosen at run
// time whose scans are bit-identical to the baseline one. bench/results/scanner.md has the measurements.
//
// Build once, scan many: SyntheticScanner builds the ray-casting scene of a SceneDescription once; Acquire()
// can then be called for any ScannerOptions (other poses, grids, noise).
#pragma once

#include <memory>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

struct ScanStats {
  int64_t rays = 0;
  int64_t returns = 0;
  // Wall-clock seconds of the scan, split between ray casting (directions and Embree) and shading (noise,
  // colour, intensity, normals, writing the channels). The two alternate band by band on every thread, so the
  // wall time is split in proportion to the time the threads spent in each.
  double cast_seconds = 0.0;
  double shade_seconds = 0.0;
};

class SyntheticScanner {
 public:
  // Builds the ray-casting scene (object i gets geometry id i). Throws InputError for a broken mesh.
  // `raycast_options` tune Embree (build quality, robust traversal); the defaults were chosen by measurement
  // (bench/results/scanner.md).
  explicit SyntheticScanner(const SceneDescription& scene, const RaycastSceneOptions& raycast_options = {});
  ~SyntheticScanner();
  SyntheticScanner(SyntheticScanner&&) noexcept;
  SyntheticScanner& operator=(SyntheticScanner&&) noexcept;

  // One scan with `options` (throws OptionsError from options.Check()). `progress` advances by rows.
  Scan Acquire(const ScannerOptions& options, Progress* progress = nullptr, ScanStats* stats = nullptr) const;
  // Same, into `scan`, whose channel buffers are reused when they have the right size (scanning many poses or
  // seeds allocates once). Buffers shared with other Scans are overwritten: pass a Scan you own.
  void AcquireInto(const ScannerOptions& options, Scan* scan, Progress* progress = nullptr,
                   ScanStats* stats = nullptr) const;

  const RaycastScene& raycast_scene() const;
  int64_t num_triangles() const;
  double build_seconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Convenience: builds the scanner for `scene` and scans with scene.scanner.
Scan SynthesizeScan(const SceneDescription& scene, Progress* progress = nullptr);

}  // namespace lidarshop
