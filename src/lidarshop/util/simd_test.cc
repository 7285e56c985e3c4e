#include "lidarshop/util/simd.h"

#include <cstdlib>
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

// Read from the environment (the library's own check of its paths may run before main): a bad value ends the
// process with exit code 2 and the message, not with a terminate.
TEST(CpuMayUseDeathTest, ABadEnvironmentValueEndsTheProcessWithItsMessage) {
  EXPECT_EXIT(
      {
        setenv("LIDARSHOP_SIMD", "sse9", 1);
        CpuMayUse("avx2");
      },
      ::testing::ExitedWithCode(2), "LIDARSHOP_SIMD=sse9: expected baseline, avx2 or avx512");
}

}  // namespace
}  // namespace lidarshop
