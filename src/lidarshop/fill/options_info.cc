// Descriptions of the hole-filling options and enums (util/options.h).
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<FillMethod>() {
  static const EnumInfo info = MakeEnumInfo<FillMethod>(
      "fill method",
      {{FillMethod::kGradient, "gradient", "range gradients inpainted by patches, then Poisson"},
       {FillMethod::kLaplace, "laplace", "membrane (Laplace) fill of range and colour"},
       {FillMethod::kDepthPatch, "depth-patch", "patches of the range itself (the thesis's failure)"},
       {FillMethod::kTelea, "telea", "OpenCV fast-marching inpainting of range and colour"}});
  return info;
}

template <>
const StructInfo& InfoOf<FillOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FillOptions> b("FillOptions", "hole filling in scans");
    b.Field(&FillOptions::method, "method", "fill method");
    b.Field(
        &FillOptions::inpaint, "inpaint",
        "patch inpainting of the patch methods (channel_weights empty and stop_for_review false: the fill "
        "decides them)");
    // The flat keys and flags of before the nesting.
    b.Alias("patch_radius", "inpaint.patch_radius").Range(1, kFillMaxPatchRadius);
    b.Alias("priority", "inpaint.priority");
    b.Alias("search", "inpaint.search");
    b.Field(&FillOptions::exact_search_max_cost, "exact_search_max_cost",
            "with patchmatch: the exact search when hole cells x scan cells is at most this; 0 = never")
        .Unit("cells x cells")
        .Min(0);
    b.Alias("search_window_radius", "inpaint.local_window_radius");
    b.Alias("patchmatch_random_samples", "inpaint.patchmatch_random_samples").Range(1, 100000);
    b.Alias("patchmatch_iterations", "inpaint.patchmatch_iterations").Range(1, 100);
    b.Alias("acceptance", "inpaint.acceptance");
    b.Alias("acceptance_local_first", "inpaint.acceptance_local_first");
    b.Field(&FillOptions::color_weight, "color_weight", "patch difference weight of each colour channel")
        .Min(0);
    b.Field(&FillOptions::gradient_weight, "gradient_weight",
            "patch difference weight of each range-gradient channel")
        .Min(0);
    b.Field(&FillOptions::return_weight, "return_weight", "patch difference weight of the has-return channel")
        .Min(0);
    b.Field(&FillOptions::offset_completion, "offset_completion",
            "complete the hole by shifted copies at the scan's dominant patch offsets first");
    b.Field(&FillOptions::offsets, "offsets",
            "offset completion's parameters (empty channel_weights = the fill's weights)");
    b.Field(&FillOptions::inverse_range, "inverse_range",
            "copy the gradients of 1/range (slowly varying on planes)");
    b.Field(
         &FillOptions::depth_jump_ratio, "depth_jump_ratio",
         "an edge whose ranges differ by more than this times the nearer one is a silhouette; 0 = never cut")
        .Min(0);
    b.Field(&FillOptions::background_only, "background_only",
            "gradient method: continue the background only (objects in front of it touching the hole are "
            "filled with it, not written; no patch copies one)");
    b.Field(&FillOptions::telea_radius_cells, "telea_radius_cells",
            "telea: neighbourhood of the fast marching")
        .Unit("cells")
        .AboveZero();
    b.Field(&FillOptions::poisson, "poisson", "range reconstruction");
    b.Field(&FillOptions::lattice, "lattice",
            "gradient method: cells copied from a repeating facade taken one or more pitches along it");
    b.Field(&FillOptions::planes, "planes", "gradient method: ranges onto the planes seen around the hole");
    b.Alias("seed", "inpaint.seed");
    b.Field(&FillOptions::window_margin, "window_margin",
            "work in the hole's bounding box grown by this times its larger side; 0 = the whole scan")
        .Unit("hole sizes")
        .Range(0, 1000);
    b.Field(&FillOptions::window_min_margin_cells, "window_min_margin_cells",
            "the window's margin around the hole is at least this")
        .Unit("cells")
        .Range(0, 1000000);
    b.Field(&FillOptions::window_min_known_ratio, "window_min_known_ratio",
            "the window is doubled until it holds this many known returns per hole cell")
        .Range(0, 1e6);
    b.Check([](const FillOptions& o) {
      if (!o.inpaint.channel_weights.empty()) {
        throw OptionsFieldError(
            "inpaint.channel_weights",
            "must be empty: the fill weighs its channels by color_weight, gradient_weight "
            "and return_weight");
      }
      if (o.inpaint.stop_for_review)
        throw OptionsFieldError("inpaint.stop_for_review", "the fill cannot stop for a review");
      if (o.inpaint.local_window_radius < o.inpaint.patch_radius) {
        throw OptionsFieldError("inpaint.local_window_radius",
                                fmt::format("{} is less than the patch radius {}",
                                            o.inpaint.local_window_radius, o.inpaint.patch_radius));
      }
      if (o.color_weight + o.gradient_weight + o.return_weight <= 0) {
        throw OptionsFieldError("color_weight", "one of the colour, gradient and return weights must be > 0");
      }
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillPlaneOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FillPlaneOptions> b(
        "FillPlaneOptions", "filled ranges onto the planes seen around the hole (fill/surface_planes.h)");
    b.Field(&FillPlaneOptions::enabled, "enabled",
            "move reconstructed ranges onto the planes around the hole");
    b.Field(&FillPlaneOptions::band_cells, "band_cells",
            "band around each part of the hole searched for planes; 0 = a quarter of its diameter (8..80)")
        .Unit("cells")
        .Range(0, 1000);
    b.Field(&FillPlaneOptions::inlier_m, "inlier_m", "RANSAC inlier distance at range 0")
        .Unit("m")
        .AboveZero();
    b.Field(&FillPlaneOptions::inlier_per_m, "inlier_per_m",
            "inlier distance added per metre of the band's median range")
        .Unit("m/m")
        .Min(0);
    b.Field(&FillPlaneOptions::max_planes, "max_planes", "planes per part of the hole").Range(1, 20);
    b.Field(&FillPlaneOptions::min_share, "min_share", "least share of the band's cells a kept plane holds")
        .Range(1e-4, 0.999);
    b.Field(&FillPlaneOptions::tolerance, "tolerance",
            "a plane is a cell's candidate when its ray intersection is within this fraction of the "
            "reconstructed range")
        .Range(1e-4, 0.999);
    b.Field(&FillPlaneOptions::agreement_m, "agreement_m",
            "the patch source's plane is preferred when within this of the reconstruction")
        .Unit("m")
        .Min(0);
    b.Field(&FillPlaneOptions::agreement_per_m, "agreement_per_m",
            "added to agreement_m per metre from the hole's border")
        .Unit("m/m")
        .Min(0);
    b.Field(&FillPlaneOptions::relief_m, "relief_m",
            "largest offset from a plane copied from the patch source")
        .Unit("m")
        .Min(0);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FacadeLatticeOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FacadeLatticeOptions> b("FacadeLatticeOptions",
                                          "copies along a repeating facade's pitch (fill/facade_lattice.h)");
    b.Field(&FacadeLatticeOptions::enabled, "enabled",
            "copy the cells filled from a repeating upright plane one or more pitches along it");
    b.Field(&FacadeLatticeOptions::min_period_m, "min_period_m", "shortest pitch sought")
        .Unit("m")
        .AboveZero();
    b.Field(&FacadeLatticeOptions::max_period_m, "max_period_m", "longest pitch sought (> min_period_m)")
        .Unit("m")
        .AboveZero();
    b.Field(
         &FacadeLatticeOptions::min_score, "min_score",
         "a plane repeats when its best shift scores this (1 = identical copies, 0 = no better than chance)")
        .Range(1e-3, 1.0);
    b.Field(&FacadeLatticeOptions::max_translates, "max_translates", "pitches tried on each side")
        .Range(1, 100);
    b.Field(&FacadeLatticeOptions::relief_m, "relief_m",
            "a cell lies on a plane within this distance (window recesses)")
        .Unit("m")
        .AboveZero();
    b.Field(&FacadeLatticeOptions::max_samples, "max_samples", "known cells compared per shift at most")
        .Min(100);
    b.Check([](const FacadeLatticeOptions& o) {
      if (o.max_period_m <= o.min_period_m)
        throw OptionsFieldError("max_period_m", "must be greater than min_period_m");
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RemoveOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RemoveOptions> b("RemoveOptions", "remove an object: cut it out, fill behind it");
    b.Field(&RemoveOptions::segment, "segment", "the cut");
    b.Field(&RemoveOptions::fill, "fill", "the fill of the hole");
    b.Field(&RemoveOptions::margin_cells, "margin_cells", "the object's mask is grown by this on every side")
        .Unit("cells")
        .Range(0, 100);
    b.Field(&RemoveOptions::keep_object, "keep_object",
            "keep the object; the fill becomes a second layer behind it");
    b.Field(&RemoveOptions::fill_enclosed_no_return, "fill_enclosed_no_return",
            "fill the cells without a return enclosed by the object");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillMetricsOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FillMetricsOptions> b("FillMetricsOptions", "quality of a fill against ground truth");
    b.Field(&FillMetricsOptions::within_m, "within_m", "tolerance of the 'within' share")
        .Unit("m")
        .AboveZero();
    b.Field(&FillMetricsOptions::floating_m, "floating_m",
            "a filled point farther than this from the truth floats")
        .Unit("m")
        .AboveZero();
    b.Field(&FillMetricsOptions::normal_window_radius, "normal_window_radius",
            "plane-fit window of the normals")
        .Unit("cells")
        .Range(1, 10);
    b.Field(&FillMetricsOptions::seam_band_cells, "seam_band_cells",
            "band outside the hole for the reference jump")
        .Unit("cells")
        .Range(1, 100);
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop

namespace lidarshop {

template <>
const StructInfo& InfoOf<FillTimings>() {
  static const StructInfo info = [] {
    StructBuilder<FillTimings> b("FillTimings", "wall seconds per step");
    b.Field(&FillTimings::gradients_s, "gradients_s", "range gradients and the joint image").Unit("s");
    b.Field(&FillTimings::inpaint_s, "inpaint_s", "patch fill").Unit("s");
    b.Field(&FillTimings::lattice_s, "lattice_s", "copies along a repeating facade").Unit("s");
    b.Field(&FillTimings::poisson_s, "poisson_s", "range reconstruction").Unit("s");
    b.Field(&FillTimings::planes_s, "planes_s", "planes around the hole and ranges onto them").Unit("s");
    b.Field(&FillTimings::placement_s, "placement_s", "points along their rays").Unit("s");
    b.Field(&FillTimings::total_s, "total_s", "everything").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillResult>() {
  static const StructInfo info = [] {
    StructBuilder<FillResult> b("FillResult", "counts of a fill (the scan and images are not JSON)");
    b.Field(&FillResult::hole_cells, "hole_cells", "cells of the mask").Unit("cells");
    b.Field(&FillResult::synthesized_cells, "synthesized_cells", "hole cells given a synthesized return")
        .Unit("cells");
    b.Field(&FillResult::no_return_cells, "no_return_cells", "hole cells left without a return")
        .Unit("cells");
    b.Field(&FillResult::unanchored_cells, "unanchored_cells",
            "cells decided 'return' but cut off from every known range (left empty)")
        .Unit("cells");
    b.Field(&FillResult::plane_cells, "plane_cells", "synthesized cells placed on a plane around the hole")
        .Unit("cells");
    b.Field(&FillResult::offset_cells, "offset_cells", "hole cells copied by offset completion")
        .Unit("cells");
    b.Field(&FillResult::patches, "patches", "patches copied");
    b.Field(&FillResult::exact_search, "exact_search", "the patch search was the exact one");
    b.Field(&FillResult::lattice_cells, "lattice_cells", "hole cells copied along a facade's pitch");
    b.Field(&FillResult::front_cells, "front_cells",
            "known cells in front of the background touching the hole, filled with it and not written")
        .Unit("cells");
    b.Field(&FillResult::lattice_pitches_m, "lattice_pitches_m", "pitch of each repeating facade (0 = none)")
        .Unit("m");
    b.Field(&FillResult::lattice_storeys_m, "lattice_storeys_m", "storey height of each (0 = none)")
        .Unit("m");
    b.Field(&FillResult::candidates_evaluated, "candidates_evaluated", "source patches compared");
    b.Field(&FillResult::window_row, "window_row", "first row of the window the fill worked in");
    b.Field(&FillResult::window_col, "window_col", "first column of the window");
    b.Field(&FillResult::window_rows, "window_rows", "rows of the window").Unit("cells");
    b.Field(&FillResult::window_cols, "window_cols", "columns of the window").Unit("cells");
    b.Field(&FillResult::timings, "timings", "wall seconds per step");
    b.Field(&FillResult::warnings, "warnings", "what looks wrong with the fill, one sentence each");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RemoveResult>() {
  static const StructInfo info = [] {
    StructBuilder<RemoveResult> b("RemoveResult", "an object removal: the cut and the fill");
    b.Field(&RemoveResult::cut, "cut", "the object's cut");
    b.Field(&RemoveResult::fill, "fill", "the fill of its hole");
    b.Field(&RemoveResult::warnings, "warnings", "the cut's and the fill's warnings, one sentence each");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
