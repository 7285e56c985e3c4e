#include <gtest/gtest.h>

#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(FillOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<FillOptions>();
  ExpectExactRoundTrip<RemoveOptions>();
  ExpectExactRoundTrip<FillMetricsOptions>();
}

TEST(FillOptionsInfo, Errors) {
  ExpectRejected<FillOptions>({{"patch_radius", 16}}, "patch_radius", "out of range [1, 15]");
  ExpectRejected<FillOptions>({{"patch_radius", 9}, {"search_window_radius", 5}}, "search_window_radius",
                              "less than the patch radius");
  ExpectRejected<FillOptions>({{"method", "magic"}}, "method", "gradient|laplace|depth-patch|telea");
  ExpectRejected<FillOptions>({{"exact_search_max_cost", -1}}, "exact_search_max_cost", "out of range >= 0");
  ExpectRejected<FillOptions>({{"offsets", {{"sweeps", 0}}}}, "offsets.sweeps", "out of range [1, 100]");
  ExpectRejected<FillOptions>({{"lattice", {{"max_period_m", 0.5}}}}, "lattice.max_period_m",
                              "must be greater than min_period_m");
  ExpectRejected<RemoveOptions>({{"fill", {{"poisson", {{"max_levels", 0}}}}}}, "fill.poisson.max_levels",
                                "out of range >= 1");
  ExpectRejected<RemoveOptions>({{"segment", {{"gmm_components", 33}}}}, "segment.gmm_components",
                                "out of range [1, 32]");
}

}  // namespace lidarshop
