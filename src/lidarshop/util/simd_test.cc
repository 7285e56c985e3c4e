#include "lidarshop/util/simd.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace lidarshop {
namespace {

TEST(CpuMayUse, NoCapIsWhatTheCpuHas) {
  EXPECT_EQ(CpuMayUse("avx2", nullptr), static_cast<bool>(__builtin_cpu_supports("avx2")));
  EXPECT_EQ(CpuMayUse("avx512f", ""), static_cast<bool>(__builtin_cpu_supports("avx512f")));
  EXPECT_EQ(CpuMayUse("avx512f", "avx512"), static_cast<bool>(__builtin_cpu_supports("avx512f")));
}

TEST(CpuMayUse, TheCapTakesAwayTheWiderPaths) {
  EXPECT_FALSE(CpuMayUse("avx512f", "avx2"));
  EXPECT_EQ(CpuMayUse("avx2", "avx2"), static_cast<bool>(__builtin_cpu_supports("avx2")));
  EXPECT_FALSE(CpuMayUse("avx2", "baseline"));
  EXPECT_FALSE(CpuMayUse("avx512f", "baseline"));
}

TEST(CpuMayUse, AnUnknownCapOrFeatureIsAnError) {
  try {
    CpuMayUse("avx2", "sse9");
    FAIL() << "no error for LIDARSHOP_SIMD=sse9";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("LIDARSHOP_SIMD=sse9"), std::string::npos) << error.what();
  }
  EXPECT_THROW(CpuMayUse("neon", nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace lidarshop
