// Descriptions of the inpainting options and enums (util/options.h): names, units, ranges, docs.
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/inpaint/offset_completion.h"
#include "lidarshop/inpaint/review.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<InpaintPriorityKind>() {
  static const EnumInfo info = MakeEnumInfo<InpaintPriorityKind>(
      "fill order",
      {{InpaintPriorityKind::kCriminisi, "criminisi", "confidence x data term (Criminisi 2004)"},
       {InpaintPriorityKind::kOnionPeel, "onion-peel", "outside in, by distance to the boundary"},
       {InpaintPriorityKind::kRandom, "random", "random front pixel (seeded)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<InpaintSearchKind>() {
  static const EnumInfo info = MakeEnumInfo<InpaintSearchKind>(
      "source search", {{InpaintSearchKind::kExhaustive, "exhaustive", "every source patch (exact)"},
                        {InpaintSearchKind::kLocal, "local", "sources within the local window"},
                        {InpaintSearchKind::kTwoStep, "two-step",
                         "local window, then the whole image if global_gain times better"},
                        {InpaintSearchKind::kPatchMatch, "patchmatch",
                         "PatchMatch random search + propagation (approximate)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<HistogramRange>() {
  static const EnumInfo info = MakeEnumInfo<HistogramRange>(
      "histogram range",
      {{HistogramRange::kFull, "full", "bins span the canvas value range"},
       {HistogramRange::kCompressed, "compressed", "bins span the two regions' own range"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<HistogramMetric>() {
  static const EnumInfo info = MakeEnumInfo<HistogramMetric>(
      "histogram metric",
      {{HistogramMetric::kIntersection, "intersection", "1 - sum of bin minima"},
       {HistogramMetric::kEarthMovers, "emd", "earth mover's distance, sum |CDF1 - CDF2| / bins"}});
  return info;
}

template <>
const StructInfo& InfoOf<MeanTestOptions>() {
  static const StructInfo info = [] {
    StructBuilder<MeanTestOptions> b("MeanTestOptions", "mean test: copied region's mean against the known");
    b.Field(&MeanTestOptions::enabled, "enabled", "run the mean test");
    b.Field(&MeanTestOptions::max_difference, "max_difference",
            "weighted RMS of |mean K - mean H| to reject at")
        .Unit("value range")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RepresentativeTestOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RepresentativeTestOptions> b("RepresentativeTestOptions",
                                               "representative colour test (per-channel medians)");
    b.Field(&RepresentativeTestOptions::enabled, "enabled", "run the representative colour test");
    b.Field(&RepresentativeTestOptions::max_difference, "max_difference",
            "|median K - median H| to reject at")
        .Unit("value range")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<HistogramTestOptions>() {
  static const StructInfo info = [] {
    StructBuilder<HistogramTestOptions> b("HistogramTestOptions", "histogram test");
    b.Field(&HistogramTestOptions::enabled, "enabled", "run the histogram test");
    b.Field(&HistogramTestOptions::bins, "bins", "bins per channel").Range(2, 256);
    b.Field(&HistogramTestOptions::range, "range", "what the bins span");
    b.Field(&HistogramTestOptions::metric, "metric", "histogram distance");
    b.Field(&HistogramTestOptions::quadrants, "quadrants",
            "compare the four half-patches apart, the worst counts");
    b.Field(&HistogramTestOptions::max_distance, "max_distance", "normalised distance to reject at")
        .Range(0, 1);
    b.Check([](const HistogramTestOptions& o) {
      if (o.max_distance <= 0) throw OptionsFieldError("max_distance", "must be > 0");
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SmoothTextureTestOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SmoothTextureTestOptions> b("SmoothTextureTestOptions", "smooth-versus-textured test");
    b.Field(&SmoothTextureTestOptions::enabled, "enabled", "run the smooth-versus-textured test");
    b.Field(&SmoothTextureTestOptions::texture_sigma, "texture_sigma", "a known region below this is smooth")
        .Unit("value range")
        .Min(0);
    b.Field(&SmoothTextureTestOptions::max_value, "max_value",
            "reject at 1 - sigma_copied / sigma_known above this")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<AcceptanceOptions>() {
  static const StructInfo info = [] {
    StructBuilder<AcceptanceOptions> b("AcceptanceOptions", "patch acceptance tests (thesis 7.1), ANDed");
    b.Field(&AcceptanceOptions::enabled, "enabled", "run the acceptance tests");
    b.Field(&AcceptanceOptions::mean, "mean", "mean test");
    b.Field(&AcceptanceOptions::representative, "representative", "representative colour test");
    b.Field(&AcceptanceOptions::histogram, "histogram", "histogram test");
    b.Field(&AcceptanceOptions::smooth_texture, "smooth_texture", "smooth-versus-textured test");
    b.Field(&AcceptanceOptions::band_px, "band_px",
            "compare only bands this wide along the hole boundary; 0 = whole regions")
        .Unit("px")
        .Min(0);
    b.Field(&AcceptanceOptions::also_known_to_known, "also_known_to_known",
            "also compare the known part with the source's pixels there");
    b.Field(&AcceptanceOptions::auto_accept_hole_fraction, "auto_accept_hole_fraction",
            "accept when hole pixels are below this fraction of the patch")
        .Range(0, 1);
    b.Field(&AcceptanceOptions::min_region_pixels, "min_region_pixels",
            "a region with fewer pixels passes (too few to judge)")
        .Min(1);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<InpaintOptions>() {
  static const StructInfo info = [] {
    StructBuilder<InpaintOptions> b("InpaintOptions", "patch-based inpainting");
    b.Field(&InpaintOptions::patch_radius, "patch_radius", "patch half-width; patches are 2r+1 wide")
        .Unit("px")
        .Range(1, 64);
    b.Field(&InpaintOptions::priority, "priority", "fill order");
    b.Field(&InpaintOptions::search, "search", "source search");
    b.Field(&InpaintOptions::channel_weights, "channel_weights",
            "per-channel weights of the patch difference; empty = all 1")
        .Min(0);
    b.Field(&InpaintOptions::seed, "seed", "seed of the random priority and of PatchMatch");
    b.Field(&InpaintOptions::normal_sigma, "normal_sigma", "blur of the hole mask for the front normals")
        .Unit("px")
        .AboveZero()
        .Max(50);
    b.Field(&InpaintOptions::alpha, "alpha", "data-term normalisation (255 for 8-bit images)")
        .Unit("image units")
        .AboveZero();
    b.Field(&InpaintOptions::data_floor, "data_floor", "added to the data term").Min(0);
    b.Field(&InpaintOptions::local_window_radius, "local_window_radius",
            "local / two-step search window half-width")
        .Unit("px")
        .Min(1);
    b.Field(&InpaintOptions::global_gain, "global_gain",
            "two-step: a distant source must be this many times better than the local one")
        .Min(1);
    b.Field(&InpaintOptions::patchmatch_random_samples, "patchmatch_random_samples",
            "PatchMatch: uniform draws per query")
        .Min(1);
    b.Field(&InpaintOptions::patchmatch_local_samples, "patchmatch_local_samples",
            "PatchMatch: draws within the local window per query")
        .Min(0);
    b.Field(&InpaintOptions::patchmatch_iterations, "patchmatch_iterations",
            "PatchMatch: propagation + random-search rounds per query")
        .Min(0);
    b.Field(&InpaintOptions::acceptance, "acceptance", "patch acceptance tests");
    b.Field(&InpaintOptions::acceptance_candidates, "acceptance_candidates",
            "ranked candidates offered to the acceptance per search step (K)")
        .Min(1);
    b.Field(&InpaintOptions::acceptance_local_first, "acceptance_local_first",
            "with acceptance: search the local window before the whole image");
    b.Field(&InpaintOptions::lookahead, "lookahead",
            "forward-looking: highest-priority targets decided at once (1 = greedy)")
        .Min(1);
    b.Field(
        &InpaintOptions::lookahead_by_margin, "lookahead_by_margin",
        "fill the passing lookahead target with the largest acceptance margin (else the highest priority)");
    b.Field(&InpaintOptions::stop_for_review, "stop_for_review",
            "stop at a target where no candidate passes and return a review");
    b.Field(&InpaintOptions::review_candidates, "review_candidates", "candidates listed in a review (N)")
        .Min(1);
    b.Field(&InpaintOptions::review_cluster_rms, "review_cluster_rms",
            "review candidates closer than this share a cluster")
        .Unit("value range")
        .Min(0);
    b.Field(&InpaintOptions::check_bookkeeping, "check_bookkeeping",
            "verify the incremental front after every fill (slow; for tests)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<OffsetCompletionOptions>() {
  static const StructInfo info = [] {
    StructBuilder<OffsetCompletionOptions> b(
        "OffsetCompletionOptions",
        "completion by shifted copies at the dominant patch offsets (He & Sun 2012)");
    b.Field(&OffsetCompletionOptions::patch_radius, "patch_radius",
            "half-width of the patches described for the offset statistics")
        .Unit("px")
        .Range(1, 32);
    b.Field(&OffsetCompletionOptions::sample_step, "sample_step",
            "grid step of the described known patches (raised to stay within max_samples)")
        .Unit("px")
        .Min(1);
    b.Field(&OffsetCompletionOptions::max_samples, "max_samples", "described patches at most").Min(100);
    b.Field(&OffsetCompletionOptions::descriptor_dims, "descriptor_dims",
            "principal components describing a patch")
        .Range(2, 64);
    b.Field(&OffsetCompletionOptions::min_offset, "min_offset", "shorter offsets are not counted (Chebyshev)")
        .Unit("px")
        .Min(1);
    b.Field(&OffsetCompletionOptions::labels, "labels", "dominant offsets kept (the labels)").Range(1, 1000);
    b.Field(&OffsetCompletionOptions::sweeps, "sweeps", "alpha-expansion sweeps over all labels")
        .Range(1, 100);
    b.Field(&OffsetCompletionOptions::channel_weights, "channel_weights",
            "per-channel weights of the seam costs; empty = all 1")
        .Min(0);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewStop>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewStop> b("ReviewStop", "where a fill stopped for a review");
    b.Field(&ReviewStop::iteration, "iteration", "fill iteration at which the fill stopped");
    b.Field(&ReviewStop::target, "target", "[row, col] of the target patch no candidate passed").Unit("px");
    b.Field(&ReviewStop::candidates, "candidates", "candidates ranked for it (the review lists them)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewCandidateSummary>() {
  static const StructInfo info = [] {
    using S = ReviewCandidateSummary;
    StructBuilder<S> b("ReviewCandidateSummary", "a source candidate of a review");
    b.Field(&S::index, "index", "its rank, 0 = best");
    b.Field(&S::source, "source", "[row, col] of the source patch's centre").Unit("px");
    b.Field(&S::difference, "difference", "its patch difference to the target");
    b.Field(&S::cluster, "cluster", "its cluster's index");
    b.Field(&S::accepted, "accepted", "the acceptance tests passed it");
    b.Field(&S::test, "test", "the test that decided (the failing one, or the one with the least margin)");
    b.Field(&S::value, "value", "that test's value");
    b.Field(&S::threshold, "threshold", "that test's threshold");
    b.Field(&S::margin, "margin", "that test's margin (negative: rejected)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewClusterSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewClusterSummary> b("ReviewClusterSummary", "a cluster of a review's candidates");
    b.Field(&ReviewClusterSummary::index, "index", "the cluster's index");
    b.Field(&ReviewClusterSummary::representative, "representative", "its best candidate's index");
    b.Field(&ReviewClusterSummary::members, "members", "its candidates' indices");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewSummary> b("ReviewSummary",
                                   "a fill stopped for a review: the target and its candidates");
    b.Field(&ReviewSummary::review_point, "review_point", "review points before this one");
    b.Field(&ReviewSummary::iteration, "iteration", "fill iteration at which the fill stopped");
    b.Field(&ReviewSummary::target, "target", "[row, col] of the target patch no candidate passed")
        .Unit("px");
    b.Field(&ReviewSummary::patch_radius, "patch_radius", "the fill's patch half-width").Unit("px");
    b.Field(&ReviewSummary::candidates, "candidates", "the ranked candidates, best first");
    b.Field(&ReviewSummary::clusters, "clusters", "the candidates grouped by look");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewDecisionSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewDecisionSummary> b("ReviewDecisionSummary", "a review's decision");
    b.Field(&ReviewDecisionSummary::target, "target", "[row, col] of the reviewed target").Unit("px");
    b.Field(&ReviewDecisionSummary::source, "source", "[row, col] of the source chosen for it").Unit("px");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewFolderSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewFolderSummary> b("ReviewFolderSummary", "review.json of an inpaint --review folder");
    b.Field(&ReviewFolderSummary::decisions, "decisions", "the decisions so far, in order");
    b.Field(&ReviewFolderSummary::review, "review", "the pending review");
    return b.Build();
  }();
  return info;
}

// In the order `lidarshop inpaint --json` has always written them.
template <>
const StructInfo& InfoOf<InpaintResult>() {
  static const StructInfo info = [] {
    StructBuilder<InpaintResult> b("InpaintResult", "counts of an inpainting (the images are not JSON)");
    b.Field(&InpaintResult::complete, "complete", "false: stopped for a review, the image is a partial fill");
    b.Field(&InpaintResult::hole_pixels, "hole_pixels", "pixels of the hole").Unit("px");
    b.Field(&InpaintResult::iterations, "iterations", "patches copied");
    b.Field(&InpaintResult::candidates_evaluated, "candidates_evaluated",
            "patch differences evaluated (including early-terminated ones)");
    b.Field(&InpaintResult::acceptance_fallbacks, "acceptance_fallbacks",
            "steps where no offered candidate was accepted (the best was used)");
    b.Field(&InpaintResult::rejected, "rejected", "candidates rejected by the acceptance tests");
    b.Field(&InpaintResult::global_searches, "global_searches",
            "targets whose local window held no accepted candidate");
    b.Field(&InpaintResult::seconds, "seconds", "wall-clock time of the fill").Unit("s");
    b.Field(&InpaintResult::review_stop, "review", "where the fill stopped for a review (only then)");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
