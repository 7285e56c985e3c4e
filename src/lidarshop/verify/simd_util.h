// Internal to the verify module: what its AVX2 loops share.
#pragma once

#include <cstdint>

#include "lidarshop/util/simd.h"

namespace lidarshop::verify_internal {

// Both the scalar and the AVX2 versions of a loop give bit-identical results; the AVX2 one is chosen when
// the CPU has it (tests pin each).
using lidarshop::BestSimdPath;
using lidarshop::SimdPath;

// For the AVX2 left-pack (keeping some lanes of a vector, in order, at the front): kLeftPack.lanes[mask]
// lists the lanes set in the 8-bit `mask`, in order, then zeros.
struct LeftPackTable {
  alignas(8) uint8_t lanes[256][8] = {};
  constexpr LeftPackTable() {
    for (int mask = 0; mask < 256; ++mask) {
      int count = 0;
      for (int lane = 0; lane < 8; ++lane) {
        if (mask & (1 << lane)) lanes[mask][count++] = static_cast<uint8_t>(lane);
      }
    }
  }
};
inline constexpr LeftPackTable kLeftPack;

}  // namespace lidarshop::verify_internal
