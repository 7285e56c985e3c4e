#include "lidarshop/util/simd.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace lidarshop {
namespace {

// Rank of a path: 0 baseline, 1 AVX2, 2 AVX-512.
int Rank(const char* name) {
  if (std::strcmp(name, "baseline") == 0) return 0;
  if (std::strcmp(name, "avx2") == 0) return 1;
  if (std::strcmp(name, "avx512") == 0 || std::strcmp(name, "avx512f") == 0) return 2;
  return -1;
}

bool CpuHas(const char* feature) {
  __builtin_cpu_init();  // may run before libgcc's own initializer of the CPU model
  if (std::strcmp(feature, "avx2") == 0) return __builtin_cpu_supports("avx2");
  if (std::strcmp(feature, "avx512f") == 0) return __builtin_cpu_supports("avx512f");
  throw std::invalid_argument(std::string("CpuMayUse: unknown feature \"") + feature + "\"");
}

}  // namespace

bool CpuMayUse(const char* feature, const char* cap) {
  const bool has = CpuHas(feature);
  if (cap == nullptr || *cap == '\0') return has;
  const int allowed = Rank(cap);
  if (allowed < 0) {
    throw std::invalid_argument(std::string("LIDARSHOP_SIMD=") + cap +
                                ": expected baseline, avx2 or avx512 (the widest instructions to use)");
  }
  return has && Rank(feature) <= allowed;
}

bool CpuMayUse(const char* feature) {
  // Static initializers may ask (before main): a bad value ends the process with its message, not a terminate.
  try {
    return CpuMayUse(feature, std::getenv("LIDARSHOP_SIMD"));
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "lidarshop: %s\n", error.what());
    std::exit(2);
  }
}

SimdPath BestSimdPath() {
  static const SimdPath best = CpuMayUse("avx2") ? SimdPath::kAvx2 : SimdPath::kScalar;
  return best;
}

}  // namespace lidarshop
