// Which SIMD path a loop takes, and 8-lane vector types for loops written once for every path.
//
// Loops that have an AVX2 version choose it with BestSimdPath() and keep a baseline (x86-64, SSE2) version
// that gives bit-identical results: tests pin both. The lanes types below are GCC vector extensions, so one
// source compiles to AVX2 inside a function marked __attribute__((target("avx2"))) and to pairs of SSE2
// registers elsewhere. Neither target has FMA, so no multiply-add is fused and both round identically.
#pragma once

#include "lidarshop/util/enum_names.h"

#include <immintrin.h>

#include <cstdint>

namespace lidarshop {

enum class SimdPath { kScalar, kAvx2 };
template <>
const EnumInfo& EnumInfoOf<SimdPath>();

// kAvx2 when the CPU has it and LIDARSHOP_SIMD allows it (checked once; safe during static initialization).
SimdPath BestSimdPath();

// Whether the CPU has `feature` ("avx2" or "avx512f") and `cap` allows it. `cap` is the value of the
// environment variable LIDARSHOP_SIMD: "baseline", "avx2" or "avx512"; null or empty: no cap. Every path gives
// bit-identical results, so the cap changes only the speed: it measures on an AVX-512 machine what an AVX2-only
// CPU takes. Throws std::invalid_argument for another value; BestSimdPath() then exits with the message.
bool CpuMayUse(const char* feature, const char* cap);
// CpuMayUse(feature, getenv("LIDARSHOP_SIMD")); BestSimdPath() and BestSsdKernel() keep their answers.
bool CpuMayUse(const char* feature);

// Every lanes function is inlined, so no vector crosses a call: GCC's note on the AVX
// calling convention does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
namespace lanes {

constexpr int kWidth = 8;
using F8 = float __attribute__((vector_size(32)));
using I8 = int32_t __attribute__((vector_size(32)));
using U8 = uint32_t __attribute__((vector_size(32)));

#define LIDARSHOP_LANES_INLINE __attribute__((always_inline)) inline

// (Element lists: GCC builds "I8{} + value" in memory, lane by lane, and stalls reloading it.)
LIDARSHOP_LANES_INLINE F8 Splat(float v) { return F8{v, v, v, v, v, v, v, v}; }
LIDARSHOP_LANES_INLINE I8 SplatInt(int32_t v) { return I8{v, v, v, v, v, v, v, v}; }
LIDARSHOP_LANES_INLINE U8 SplatUint(uint32_t v) { return U8{v, v, v, v, v, v, v, v}; }

template <typename V, typename T>
LIDARSHOP_LANES_INLINE V Load(const T* values) {
  V result;
  __builtin_memcpy(&result, values, sizeof(V));
  return result;
}
template <typename V, typename T>
LIDARSHOP_LANES_INLINE void Store(T* values, V vector) {
  __builtin_memcpy(values, &vector, sizeof(V));
}
// values[index[i]] per lane.
template <typename V, typename T>
LIDARSHOP_LANES_INLINE V Gather(const T* values, I8 index) {
  V result;
  for (int lane = 0; lane < kWidth; ++lane) result[lane] = values[index[lane]];
  return result;
}

// Gathers of floats as a policy for lanes code: FloatGather loads lane by lane (every path); Avx2FloatGather
// is one vgatherdps, for code compiled into a function marked target("avx2") and flatten (which inlines it
// there; elsewhere it stays a call into AVX2 code). Both load the same values.
struct FloatGather {
  LIDARSHOP_LANES_INLINE F8 operator()(const float* values, I8 index) const {
    return Gather<F8>(values, index);
  }
};
struct Avx2FloatGather {
  __attribute__((target("avx2"))) F8 operator()(const float* values, I8 index) const {
    return reinterpret_cast<F8>(_mm256_i32gather_ps(values, reinterpret_cast<__m256i>(index), 4));
  }
};

// A bijective 32-bit mixer per lane (the "lowbias32" constants): hashes for noise and procedural textures.
LIDARSHOP_LANES_INLINE U8 Mix32(U8 h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// True if any lane of `mask` is set.
LIDARSHOP_LANES_INLINE bool Any(I8 mask) {
  int any = 0;
  for (int lane = 0; lane < kWidth; ++lane) any |= mask[lane];
  return any != 0;
}

LIDARSHOP_LANES_INLINE I8 ToInt(F8 x) { return __builtin_convertvector(x, I8); }  // truncates
LIDARSHOP_LANES_INLINE F8 ToFloat(I8 x) { return __builtin_convertvector(x, F8); }
// floor for |x| < 2^31 (a truncation and a compare: the baseline has no roundps).
LIDARSHOP_LANES_INLINE F8 Floor(F8 x) {
  const F8 truncated = ToFloat(ToInt(x));
  return truncated > x ? truncated - 1.0f : truncated;
}
LIDARSHOP_LANES_INLINE F8 Min(F8 a, F8 b) { return a < b ? a : b; }
LIDARSHOP_LANES_INLINE F8 Max(F8 a, F8 b) { return a > b ? a : b; }
LIDARSHOP_LANES_INLINE F8 Clamp(F8 x, float low, float high) { return Min(Max(x, Splat(low)), Splat(high)); }
LIDARSHOP_LANES_INLINE F8 Abs(F8 x) { return x < 0.0f ? -x : x; }
// Correctly rounded (IEEE) on both paths. With -fno-math-errno (the modules' flags) this is one vsqrtps
// under AVX2 and two sqrtps on the baseline.
LIDARSHOP_LANES_INLINE F8 Sqrt(F8 x) {
  F8 result;
  for (int lane = 0; lane < kWidth; ++lane) result[lane] = __builtin_sqrtf(x[lane]);
  return result;
}

// The low byte of each lane, as 8 bytes (two byte shuffles under AVX2).
using B8 = uint8_t __attribute__((vector_size(8)));
LIDARSHOP_LANES_INLINE B8 LowBytes(I8 x) {
  using B32 = uint8_t __attribute__((vector_size(32)));
  const B32 bytes = reinterpret_cast<B32&>(x);
  return __builtin_shufflevector(bytes, bytes, 0, 4, 8, 12, 16, 20, 24, 28);
}

}  // namespace lanes
#pragma GCC diagnostic pop
}  // namespace lidarshop
