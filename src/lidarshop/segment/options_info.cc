// Descriptions of the segmentation options and enums (util/options.h).
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<SegmentMethod>() {
  static const EnumInfo info = MakeEnumInfo<SegmentMethod>(
      "segmentation method",
      {{SegmentMethod::kTwoStep, "two-step", "depth cut, background inference, colour cut"},
       {SegmentMethod::kDepth, "depth", "one range-dominant cut"},
       {SegmentMethod::kColor, "color", "one colour-dominant cut"},
       {SegmentMethod::kRgbd, "rgbd", "one cut with standardized RGB + range weights"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<AppearanceModel>() {
  static const EnumInfo info = MakeEnumInfo<AppearanceModel>(
      "appearance model", {{AppearanceModel::kHistogram, "histogram", "colour and range histograms"},
                           {AppearanceModel::kGmm, "gmm", "Gaussian mixtures (colour 3-D, range 1-D)"}});
  return info;
}

template <>
const StructInfo& InfoOf<CutWeights>() {
  static const StructInfo info = [] {
    StructBuilder<CutWeights> b("CutWeights", "weights of one graph cut (dimensionless)");
    b.Field(&CutWeights::lambda_r, "lambda_r", "n-link weight of red").Min(0);
    b.Field(&CutWeights::lambda_g, "lambda_g", "n-link weight of green").Min(0);
    b.Field(&CutWeights::lambda_b, "lambda_b", "n-link weight of blue").Min(0);
    b.Field(&CutWeights::lambda_d, "lambda_d", "n-link weight of range").Min(0);
    b.Field(&CutWeights::smoothness, "smoothness", "n-link weight relative to the data term (gamma)").Min(0);
    b.Field(&CutWeights::color_data_weight, "color_data_weight", "weight of -log P(rgb) in the data term")
        .Min(0);
    b.Field(&CutWeights::depth_data_weight, "depth_data_weight", "weight of -log P(range) in the data term")
        .Min(0);
    b.Field(&CutWeights::foreground_bias, "foreground_bias",
            "added to the object cost of every non-stroke cell")
        .Unit("nats");
    b.Field(&CutWeights::median_sigma, "median_sigma",
            "sigma^2 from the median n-link difference, not the mean");
    b.Check([](const CutWeights& w) {
      if (w.lambda_r + w.lambda_g + w.lambda_b + w.lambda_d <= 0) {
        throw OptionsFieldError("lambda_d", "at least one channel weight lambda must be > 0");
      }
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<WholeObjectOptions>() {
  static const StructInfo info = [] {
    StructBuilder<WholeObjectOptions> b("WholeObjectOptions",
                                        "growth of the cut into parts continuous in depth and orientation");
    b.Field(&WholeObjectOptions::jump_cells, "jump_cells",
            "depth continuity: largest range step, in cell spacings at the cell's range")
        .AboveZero();
    b.Field(&WholeObjectOptions::min_jump_m, "min_jump_m", "floor of the depth-continuity threshold")
        .Unit("m")
        .Min(0);
    b.Field(&WholeObjectOptions::max_crease_deg, "max_crease_deg",
            "largest angle between neighbouring normals inside one object")
        .Unit("deg")
        .AboveZero()
        .Max(180);
    b.Field(&WholeObjectOptions::normal_window_cells, "normal_window_cells",
            "half-width of the grid window of the normals")
        .Unit("cells")
        .Min(1);
    b.Field(&WholeObjectOptions::max_growth, "max_growth",
            "growth larger than this times the object's cells is a leak and is dropped")
        .Min(0);
    b.Field(&WholeObjectOptions::support_band_cells, "support_band_cells",
            "support planes are fitted to the cells this far around the cut")
        .Unit("cells")
        .Min(1);
    b.Field(&WholeObjectOptions::support_distance_m, "support_distance_m",
            "cells this close to a support plane and parallel to it are support, never object")
        .Unit("m")
        .AboveZero();
    b.Field(&WholeObjectOptions::support_max_tilt_deg, "support_max_tilt_deg",
            "a cell near a support plane is support when its normal is within this angle of the plane's")
        .Unit("deg")
        .AboveZero()
        .Max(90);
    b.Field(&WholeObjectOptions::free_support_seeds, "free_support_seeds",
            "step 3 does not force step 1's cells on a support plane into the object");
    b.Field(&WholeObjectOptions::join_overhangs, "join_overhangs",
            "a part in front of the object held by nothing else visible joins it");
    b.Field(&WholeObjectOptions::overhang_max_contact, "overhang_max_contact",
            "an overhang meets the object along at most this fraction of its outline")
        .Min(0)
        .Max(1);
    b.Field(&WholeObjectOptions::join_steps, "join_steps",
            "a closed part across a depth step, touching the object in space, joins it (a post under a box)");
    b.Field(&WholeObjectOptions::join_max_gap_m, "join_max_gap_m",
            "... when its cell next to the object lies this close to the object's in space")
        .Unit("m")
        .Min(0);
    b.Field(&WholeObjectOptions::join_max_crease_deg, "join_max_crease_deg",
            "... and its neighbouring normals lie within this angle (a square post's corner)")
        .Unit("deg")
        .AboveZero()
        .Max(180);
    b.Field(&WholeObjectOptions::join_rests_on, "join_rests_on",
            "a closed part in front of the object and below it, that the object stands on, joins it");
    b.Field(&WholeObjectOptions::rests_on_max_growth, "rests_on_max_growth",
            "... up to this many times the object's cells in all")
        .Min(0);
    b.Field(&WholeObjectOptions::separate_touching, "separate_touching",
            "parts of the depth cut cut off from the stroked part by crevices are a touching neighbour");
    b.Field(&WholeObjectOptions::crevice_flank_deg, "crevice_flank_deg",
            "both flanks of a crevice between touching bodies rise at least this steeply")
        .Unit("deg")
        .AboveZero()
        .Max(89);
    b.Field(&WholeObjectOptions::crevice_baseline_cells, "crevice_baseline_cells",
            "the rise of a crevice's flanks is measured over this many cells")
        .Unit("cells")
        .Range(1, 32);
    b.Field(&WholeObjectOptions::neighbour_min_fraction, "neighbour_min_fraction",
            "smaller parts, as a fraction of the stroked parts' cells, stay with the object")
        .Min(0);
    b.Field(&WholeObjectOptions::strip_max_cells, "strip_max_cells",
            "the cuts drop strips of at most this many rows they follow along the scene (0 = keeps them)")
        .Unit("cells")
        .Min(0);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SegmentOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SegmentOptions> b("SegmentOptions", "two-step RGB + depth graph cuts");
    b.Field(&SegmentOptions::method, "method", "segmentation method");
    b.Field(&SegmentOptions::model, "model", "appearance model");
    b.Field(&SegmentOptions::eight_connected, "eight_connected", "8-neighbour n-links instead of 4");
    b.Field(&SegmentOptions::sigma_scale, "sigma_scale", "sigma^2 = sigma_scale^2 x mean n-link difference")
        .AboveZero();
    b.Field(&SegmentOptions::depth_step, "depth_step", "step 1 / the depth baseline");
    b.Field(&SegmentOptions::color_step, "color_step", "step 3 / the colour baseline");
    b.Field(&SegmentOptions::rgbd_step, "rgbd_step", "the rgbd baseline");
    b.Field(&SegmentOptions::ring_radius_cells, "ring_radius_cells", "step 2: dilation of the step-1 object")
        .Unit("cells")
        .Range(1, 64);
    b.Field(&SegmentOptions::ring_depth_threshold_m, "ring_depth_threshold_m",
            "step 2: a ring cell farther than this from the object is background")
        .Unit("m")
        .Min(0);
    b.Field(&SegmentOptions::ring_depth_threshold_fraction, "ring_depth_threshold_fraction",
            "step 2: plus this fraction of its range")
        .Min(0);
    b.Field(&SegmentOptions::roi_margin_cells, "roi_margin_cells",
            "step 3 region of interest margin; 0 = whole image")
        .Unit("cells")
        .Min(0);
    b.Field(&SegmentOptions::roi_margin_fraction, "roi_margin_fraction",
            "step 3 margin as a fraction of the object box's larger side")
        .Min(0);
    b.Field(&SegmentOptions::window_margin_cells, "window_margin_cells",
            "the cuts' graphs cover the strokes' box grown by this, doubled while the cut reaches its edge; "
            "0 = whole scan")
        .Unit("cells")
        .Min(0);
    b.Field(&SegmentOptions::coarse_max_cells, "coarse_max_cells",
            "a scan of more cells is cut on a coarser level (every f-th ray) and its outline re-cut at full "
            "resolution; 0 = always full resolution")
        .Unit("cells")
        .Min(0);
    b.Field(&SegmentOptions::color_bins, "color_bins", "histogram bins per colour channel").Range(2, 64);
    b.Field(&SegmentOptions::depth_bin_m, "depth_bin_m", "range histogram bin width").Unit("m").AboveZero();
    b.Field(&SegmentOptions::depth_smoothing_m, "depth_smoothing_m",
            "Gaussian smoothing of the range histogram")
        .Unit("m")
        .Min(0);
    b.Field(&SegmentOptions::gmm_components, "gmm_components", "Gaussians per mixture").Range(1, 32);
    b.Field(&SegmentOptions::gmm_iterations, "gmm_iterations", "EM iterations").Range(0, 1000);
    b.Field(&SegmentOptions::seed, "seed", "seed of the mixtures' k-means++ initialisation");
    b.Field(&SegmentOptions::object_uniform, "object_uniform",
            "weight of the uniform density in the object model")
        .AboveZero()
        .Below(1);
    b.Field(&SegmentOptions::background_uniform, "background_uniform",
            "weight of the uniform density in the background model")
        .AboveZero()
        .Below(1);
    b.Field(&SegmentOptions::refine_relearn_models, "refine_relearn_models",
            "refinement re-learns the appearance models from every hard cell");
    b.Field(&SegmentOptions::refine_monotone, "refine_monotone",
            "a refinement with only background strokes only removes cells, one with only object strokes only "
            "adds");
    b.Field(&SegmentOptions::scale_to_data, "scale_to_data",
            "scale the metric lengths by the ray spacing measured at the object strokes");
    b.Field(&SegmentOptions::reference_spacing_m, "reference_spacing_m",
            "ray spacing at the object the metric lengths are given for")
        .Unit("m")
        .AboveZero();
    b.Field(&SegmentOptions::grow_whole_object, "grow_whole_object",
            "two-step: parts continuous in depth and orientation with the cut join it");
    b.Field(&SegmentOptions::contain_leaks, "contain_leaks",
            "two-step: a cut far past the part its object strokes lie on leaked; that part is taken instead");
    b.Field(&SegmentOptions::whole_object, "whole_object", "the whole-object growth");
    b.Field(&SegmentOptions::include_enclosed_no_return, "include_enclosed_no_return",
            "cells without a return enclosed by the object join the mask");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop

namespace lidarshop {

template <>
const StructInfo& InfoOf<SegmentTimings>() {
  static const StructInfo info = [] {
    StructBuilder<SegmentTimings> b("SegmentTimings", "wall seconds per stage");
    b.Field(&SegmentTimings::features_s, "features_s", "standardized features").Unit("s");
    b.Field(&SegmentTimings::models_s, "models_s", "appearance models").Unit("s");
    b.Field(&SegmentTimings::graph_s, "graph_s", "graph construction").Unit("s");
    b.Field(&SegmentTimings::maxflow_s, "maxflow_s", "max-flow").Unit("s");
    b.Field(&SegmentTimings::total_s, "total_s", "everything").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SegmentResult>() {
  static const StructInfo info = [] {
    StructBuilder<SegmentResult> b("SegmentResult", "a cut (the mask itself is an image, not JSON)");
    b.Field(&SegmentResult::object_cells, "object_cells", "cells of the object").Unit("cells");
    b.Field(&SegmentResult::graph_nodes, "graph_nodes", "nodes of the last cut's graph");
    b.Field(&SegmentResult::flow, "flow", "value of the last max-flow");
    b.Field(&SegmentResult::window_row, "window_row", "first row of the window the cuts' graphs covered");
    b.Field(&SegmentResult::window_col, "window_col", "first column of the window");
    b.Field(&SegmentResult::window_rows, "window_rows", "rows of the window").Unit("cells");
    b.Field(&SegmentResult::window_cols, "window_cols", "columns of the window").Unit("cells");
    b.Field(&SegmentResult::window_growths, "window_growths", "times the window was grown");
    b.Field(&SegmentResult::coarse_factor, "coarse_factor",
            "1 = cut at full resolution; f = on every f-th ray, the outline re-cut at full resolution");
    b.Field(&SegmentResult::ray_spacing_m, "ray_spacing_m",
            "spacing of neighbouring rays at the object strokes")
        .Unit("m");
    b.Field(&SegmentResult::length_scale, "length_scale",
            "factor applied to the metric lengths (scale_to_data)");
    b.Field(&SegmentResult::timings, "timings", "wall seconds per stage");
    b.Field(&SegmentResult::warnings, "warnings", "what looks wrong with the cut, one sentence each");
    b.Field(&SegmentResult::refined, "refined", "extra strokes refined a first cut (where a caller says)");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
