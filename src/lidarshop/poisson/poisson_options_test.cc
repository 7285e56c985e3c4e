#include <gtest/gtest.h>

#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(PoissonOptionsInfo, ExactRoundTrip) { ExpectExactRoundTrip<PoissonOptions>(); }

TEST(PoissonOptionsInfo, Errors) {
  ExpectRejected<PoissonOptions>({{"tolerance", 1.0}}, "tolerance", "out of range (0, 1)");
  ExpectRejected<PoissonOptions>({{"solver", "cholmod"}}, "solver", "auto|direct|multigrid");
  EXPECT_EQ(ToString(PoissonDirectBackend::kEigenLdlt), "eigen-ldlt");
}

}  // namespace lidarshop
