#include "lidarshop/util/simd.h"

namespace lidarshop {

SimdPath BestSimdPath() {
  static const SimdPath best = [] {
    __builtin_cpu_init();  // may run before libgcc's own initializer of the CPU model
    return __builtin_cpu_supports("avx2") ? SimdPath::kAvx2 : SimdPath::kScalar;
  }();
  return best;
}

}  // namespace lidarshop
