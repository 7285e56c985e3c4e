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

// The result's JSON keys in the order `lidarshop inpaint --json` has always written them; "review" only when
// the fill stopped for one.
TEST(InpaintOptionsInfo, ResultKeys) {
  ExpectExactRoundTrip<InpaintResult>();
  ExpectExactRoundTrip<ReviewStop>();
  EXPECT_EQ(
      InfoOf<InpaintResult>().Keys(),
      (std::vector<std::string>{"complete", "hole_pixels", "iterations", "candidates_evaluated",
                                "acceptance_fallbacks", "rejected", "global_searches", "seconds", "review"}));
  InpaintResult result;
  result.hole_pixels = 9;
  EXPECT_EQ(ToJson(result).dump(),
            R"({"complete":true,"hole_pixels":9,"iterations":0,"candidates_evaluated":0,)"
            R"("acceptance_fallbacks":0,"rejected":0,"global_searches":0,"seconds":0.0})");
  InpaintReview review;
  review.iteration = 4;
  review.target = {10, 20};
  review.candidates.resize(3);
  result.complete = false;
  result.review_stop = StopOf(review);
  EXPECT_EQ(ToJson(result)["review"].dump(), R"({"iteration":4,"target":[10,20],"candidates":3})");
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
