// Hand-made scans by analytic ray casting, for tests that need exact geometry (pillars, blocks) without the
// synthetic scanner's meshes: a uniform grid of rays from the origin, the caller's first-hit function per ray,
// Gaussian range noise and a shared Gaussian colour jitter per cell from one seeded generator.
#pragma once

#include <cstdint>
#include <functional>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop::test_scenes {

struct RayHit {
  double range_m = 0;  // along the unit ray
  cv::Vec3b rgb;
  int label = 0;
};

// The backdrop of the segment tests: a beige wall across y = wall_y_m and a ground plane 1.5 m below the scanner
// (`ground_rgb`), whichever the ray meets first; label 0.
RayHit WallAndGround(const cv::Vec3f& direction, double wall_y_m, const cv::Vec3b& ground_rgb);

struct AnalyticGrid {
  int rows = 0, cols = 0;
  double azimuth_min_deg = 0, azimuth_max_deg = 0, elevation_min_deg = 0, elevation_max_deg = 0;
};

// Every cell gets a return at `hit(direction)`'s range plus N(0, range_noise_m²) and its colour plus
// 5·N(0, 1) grey levels on every channel (one draw per cell, before the range's).
Scan MakeAnalyticScan(const AnalyticGrid& grid, const std::function<RayHit(const cv::Vec3f&)>& hit,
                      double range_noise_m, uint64_t seed);

}  // namespace lidarshop::test_scenes
