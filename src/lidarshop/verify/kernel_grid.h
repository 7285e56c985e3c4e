// Internal to the verify module: building the KernelNeighbourGrid (verify.h) and its two queries, the hot
// loops of the confidence measure and of the trimmed-ICP baseline. The queries run 8 model points per
// instruction with AVX2 where the CPU has it (checked once at run time; Debian builds for plain x86-64) and
// give bit-identical results on the scalar path: no FMA contraction, the same summation order, hits visited
// in the same order.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lidarshop/verify/simd_util.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::verify_internal {

// exp(x) for the confidence kernel, x = −d²/2σ² in [−87, 0] (clamped below): 2ⁿ · e^r with n = round(x / ln
// 2) and the degree-7 Taylor polynomial of e^r, |r| ≤ ln 2 / 2 (truncation < 1e-8 relative; within 2 ulp of
// std::exp, tested), evaluated by Estrin's scheme (a shorter dependency chain than Horner's). Written out
// so that the AVX2 kernel computes the very same operations 8 at a time: both paths (and the KD-tree
// fallback) give bit-identical sums.
inline float KernelExp(float x) {
  x = std::max(x, -87.0f);
  const float n = std::nearbyint(x * 1.44269504f);
  const float r = (x - n * 0.693145751953125f) - n * 1.42860682030941723212e-6f;
  const float r2 = r * r, r4 = r2 * r2;
  const float low = (1.0f + r) + r2 * (0.5f + r * (1.0f / 6.0f));
  const float high = (1.0f / 24.0f + r * (1.0f / 120.0f)) + r2 * (1.0f / 720.0f + r * (1.0f / 5040.0f));
  return (low + r4 * high) * std::bit_cast<float>((static_cast<int32_t>(n) + 127) << 23);
}

// Both grids over `bounds` (the model's box) grown by max(kernel_radius, trim).
KernelNeighbourGrid BuildKernelGrid(std::span<const Eigen::Vector3f> points,
                                    const Eigen::AlignedBox3f& bounds, float kernel_radius, float trim);

// The kernel step for scene points (model frame, inside the grids' box), in order: for every model point
// with d² = |p − m|² < radius_sq, sum[k] += exp(−d² · inverse_two_sigma_sq) unless sum[k] ≥ 1 already (only
// min(1, sum) is used, so this is exact), where k is the point's slot in the kernel grid's sorted order
// (grid.kernel.indices[k] is its model point index). closest_sq[j] = the smallest such d² of points[j]
// (+inf when none). Fastest when consecutive points are neighbours (scan order).
void AccumulateKernel(const KernelNeighbourGrid& grid, std::span<const Eigen::Vector3f> points,
                      float radius_sq, float inverse_two_sigma_sq, float* sum, float* closest_sq,
                      SimdPath path = BestSimdPath());

// closest_sq[j] = the squared distance from points[j] (model frame) to its nearest model point when that is
// within the ICP grid's radius (the trim distance); otherwise some value > trim² (possibly +inf).
void NearestSquaredDistance(const KernelNeighbourGrid& grid, std::span<const Eigen::Vector3f> points,
                            float* closest_sq, SimdPath path = BestSimdPath());

}  // namespace lidarshop::verify_internal
