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

// Fill's inpainting is InpaintOptions nested (described once, in inpaint/options_info.cc); the nine flat keys
// of before are aliases that set the nested fields.
TEST(FillOptionsInfo, InpaintingIsNested) {
  const StructInfo& info = InfoOf<FillOptions>();
  ASSERT_NE(info.Find("inpaint"), nullptr);
  EXPECT_EQ(info.Find("inpaint")->nested, &InfoOf<InpaintOptions>());
  for (const char* key :
       {"patch_radius", "priority", "search", "search_window_radius", "patchmatch_random_samples",
        "patchmatch_iterations", "acceptance", "acceptance_local_first", "seed"}) {
    EXPECT_EQ(info.Find(key), nullptr) << key << " is a field of its own";
    EXPECT_NE(info.FindAlias(key), nullptr) << key << " is no alias";
  }
  EXPECT_EQ(info.FindAlias("search_window_radius")->alias_of, "inpaint.local_window_radius");
  // The fill's defaults, as before the nesting.
  const FillOptions defaults;
  EXPECT_EQ(defaults.inpaint.patch_radius, 4);
  EXPECT_EQ(defaults.inpaint.search, InpaintSearchKind::kPatchMatch);
  EXPECT_EQ(defaults.inpaint.local_window_radius, 50);
  EXPECT_EQ(defaults.inpaint.priority, InpaintPriorityKind::kCriminisi);
  EXPECT_EQ(defaults.inpaint.patchmatch_random_samples, 48);
  EXPECT_EQ(defaults.inpaint.patchmatch_iterations, 4);
  EXPECT_EQ(ToJson(defaults.inpaint.acceptance), ToJson(AcceptanceOptions::Combined()));
  EXPECT_TRUE(defaults.inpaint.acceptance_local_first);
  EXPECT_EQ(defaults.inpaint.seed, 0u);
  EXPECT_TRUE(defaults.inpaint.channel_weights.empty());
  // The old keys set the nested fields; the JSON form is nested only.
  const FillOptions o = FromJson<FillOptions>({{"patch_radius", 6},
                                               {"priority", "onion-peel"},
                                               {"search", "local"},
                                               {"search_window_radius", 30},
                                               {"patchmatch_random_samples", 12},
                                               {"patchmatch_iterations", 2},
                                               {"acceptance", {{"enabled", false}, {"band_px", 3}}},
                                               {"acceptance_local_first", false},
                                               {"seed", 17}});
  EXPECT_EQ(o.inpaint.patch_radius, 6);
  EXPECT_EQ(o.inpaint.priority, InpaintPriorityKind::kOnionPeel);
  EXPECT_EQ(o.inpaint.search, InpaintSearchKind::kLocal);
  EXPECT_EQ(o.inpaint.local_window_radius, 30);
  EXPECT_EQ(o.inpaint.patchmatch_random_samples, 12);
  EXPECT_EQ(o.inpaint.patchmatch_iterations, 2);
  EXPECT_FALSE(o.inpaint.acceptance.enabled);
  EXPECT_EQ(o.inpaint.acceptance.band_px, 3);
  EXPECT_TRUE(o.inpaint.acceptance.representative.enabled);  // the rest of the combined set stays
  EXPECT_FALSE(o.inpaint.acceptance_local_first);
  EXPECT_EQ(o.inpaint.seed, 17u);
  const nlohmann::ordered_json json = ToJson(o);
  EXPECT_EQ(json["inpaint"]["local_window_radius"], 30);
  for (const char* key : {"patch_radius", "search_window_radius", "seed", "acceptance"})
    EXPECT_FALSE(json.contains(key)) << key;
  EXPECT_EQ(ToJson(FromJson<FillOptions>(json)), json);
  // Inside RemoveOptions too (its "fill").
  EXPECT_EQ(
      FromJson<RemoveOptions>({{"fill", {{"search_window_radius", 33}}}}).fill.inpaint.local_window_radius,
      33);
}

TEST(FillOptionsInfo, Errors) {
  ExpectRejected<FillOptions>({{"patch_radius", 16}}, "patch_radius", "out of range [1, 15]");
  ExpectRejected<FillOptions>({{"patch_radius", 9}, {"search_window_radius", 5}},
                              "inpaint.local_window_radius", "less than the patch radius");
  ExpectRejected<FillOptions>({{"inpaint", {{"patch_radius", 16}}}}, "inpaint.patch_radius",
                              "out of range [1, 15]");
  ExpectRejected<FillOptions>({{"inpaint", {{"patch_radius", 65}}}}, "inpaint.patch_radius",
                              "out of range [1, 64]");
  ExpectRejected<FillOptions>({{"inpaint", {{"channel_weights", {1, 1}}}}}, "inpaint.channel_weights",
                              "color_weight");
  ExpectRejected<FillOptions>({{"inpaint", {{"stop_for_review", true}}}}, "inpaint.stop_for_review",
                              "cannot stop");
  ExpectRejected<FillOptions>({{"seed", 1}, {"inpaint", {{"seed", 2}}}}, "seed",
                              "also given as inpaint.seed");
  ExpectRejected<FillOptions>({{"acceptance", {{"band_pix", 2}}}}, "acceptance.band_pix",
                              "did you mean 'band_px'");
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
