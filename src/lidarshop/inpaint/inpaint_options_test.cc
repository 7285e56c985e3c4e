#include <gtest/gtest.h>

#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/inpaint/offset_completion.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(InpaintOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<InpaintOptions>();
  ExpectExactRoundTrip<AcceptanceOptions>();
  ExpectExactRoundTrip<MeanTestOptions>();
  ExpectExactRoundTrip<RepresentativeTestOptions>();
  ExpectExactRoundTrip<HistogramTestOptions>();
  ExpectExactRoundTrip<SmoothTextureTestOptions>();
  ExpectExactRoundTrip<OffsetCompletionOptions>();
}

TEST(InpaintOptionsInfo, Errors) {
  ExpectRejected<InpaintOptions>({{"patch_radius", 65}}, "patch_radius", "out of range [1, 64]");
  ExpectRejected<InpaintOptions>({{"search", "patch-match"}}, "search", "did you mean 'patchmatch'");
  ExpectRejected<InpaintOptions>({{"acceptance", {{"histogram", {{"bins", 1}}}}}},
                                 "acceptance.histogram.bins", "out of range [2, 256]");
  ExpectRejected<OffsetCompletionOptions>({{"labels", 0}}, "labels", "out of range [1, 1000]");
  ExpectRejected<OffsetCompletionOptions>({{"channel_weights", {1.0, -1.0}}}, "channel_weights", ">= 0");
  EXPECT_EQ(ToString(InpaintSearchKind::kTwoStep), "two-step");
  EXPECT_EQ(ToString(HistogramMetric::kEarthMovers), "emd");
}

TEST(InpaintOptionsInfo, CheckUsesTheDescription) {
  InpaintOptions options;
  options.global_gain = 0.5;
  EXPECT_THROW(options.Check(), OptionsFieldError);
}

}  // namespace lidarshop
