// Descriptions of the verification options, enums and result (util/options.h).
#include "lidarshop/util/options.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<ModelPointSource>() {
  static const EnumInfo info = MakeEnumInfo<ModelPointSource>(
      "model point source",
      {{ModelPointSource::kSurfaceSamples, "surface-samples", "uniform over the surface area"},
       {ModelPointSource::kVertices, "vertices", "the mesh's vertices (the original work)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<InformationWeighting>() {
  static const EnumInfo info = MakeEnumInfo<InformationWeighting>(
      "information weighting", {{InformationWeighting::kUniform, "uniform", "every model point carries 1/N"},
                                {InformationWeighting::kShapeDistinctiveness, "shape-distinctiveness",
                                 "in proportion to surface variation"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<SweepSearch>() {
  static const EnumInfo info = MakeEnumInfo<SweepSearch>(
      "sweep search", {{SweepSearch::kFull, "full", "verify every grid pose"},
                       {SweepSearch::kCoarseToFine, "coarse-to-fine",
                        "verify only the poses whose confidence bound can pass (same detections)"}});
  return info;
}

template <>
const StructInfo& InfoOf<ModelOptions>() {
  static const StructInfo info = [] {
    StructBuilder<ModelOptions> b("ModelOptions", "the model side of verification");
    b.Field(&ModelOptions::model_scale, "model_scale",
            "metres per mesh unit: the mesh is scaled by this first (0.001 for a mesh in millimetres)")
        .Range(1e-6, 1e6);
    b.Field(&ModelOptions::point_source, "point_source", "where the model points come from");
    b.Field(&ModelOptions::num_surface_samples, "num_surface_samples", "model points (surface samples)")
        .Range(1, static_cast<double>(ModelOptions::kMaxSurfaceSamples));
    b.Field(&ModelOptions::seed, "seed", "seed of the surface sampling");
    b.Field(&ModelOptions::information, "information", "how the information of the model points is spread");
    b.Field(&ModelOptions::distinctiveness_radius_m, "distinctiveness_radius_m",
            "neighbourhood of the surface variation; 0 = 3% of the bounding-box diagonal")
        .Unit("m")
        .Min(0);
    b.Field(&ModelOptions::distinctiveness_floor, "distinctiveness_floor", "added to every point's variation")
        .Min(0);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<VerifyOptions>() {
  static const StructInfo info = [] {
    // Lengths past 1 km are not physical for an object in a terrestrial scan (and would overflow the
    // neighbour grid's cell arithmetic).
    StructBuilder<VerifyOptions> b("VerifyOptions", "consistency and confidence of a pose (thesis ch. 4)");
    b.Field(&VerifyOptions::allowance_m, "allowance_m", "a: how far behind the model a scan point may lie")
        .Unit("m")
        .Range(0, 1000);
    b.Field(&VerifyOptions::sigma_m, "sigma_m", "sigma of the confidence kernel, about the point spacing")
        .Unit("m")
        .AboveZero()
        .Max(1000);
    b.Field(&VerifyOptions::icp_trim_m, "icp_trim_m", "ICP pairs beyond this are excluded")
        .Unit("m")
        .AboveZero()
        .Max(1000);
    b.Field(&VerifyOptions::footprint_margin_cells, "footprint_margin_cells",
            "cells around the model's footprint")
        .Unit("cells")
        .Min(0)
        .Below(1000);
    b.Field(&VerifyOptions::keep_details, "keep_details",
            "keep the per-cell status and per-point information");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SweepOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SweepOptions> b("SweepOptions", "verification over a grid of candidate poses");
    b.Field(&SweepOptions::x_min_m, "x_min_m", "world x range of the model origin, from").Unit("m");
    b.Field(&SweepOptions::x_max_m, "x_max_m", "to").Unit("m");
    b.Field(&SweepOptions::y_min_m, "y_min_m", "world y range, from").Unit("m");
    b.Field(&SweepOptions::y_max_m, "y_max_m", "to").Unit("m");
    b.Field(&SweepOptions::step_m, "step_m", "between candidate positions").Unit("m").AboveZero();
    b.Field(&SweepOptions::z_m, "z_m", "world z of the model origin").Unit("m");
    b.Field(&SweepOptions::yaws_deg, "yaws_deg", "yaws tried at every position").Unit("deg");
    b.Field(&SweepOptions::min_consistency, "min_consistency", "detections need consistency above this")
        .Range(0, 1);
    b.Field(&SweepOptions::min_confidence, "min_confidence", "and confidence above this").Range(0, 1);
    b.Field(&SweepOptions::min_comparable_pairs, "min_comparable_pairs",
            "and at least this many comparable pairs")
        .Min(0);
    b.Field(&SweepOptions::nms_radius_m, "nms_radius_m", "non-maximum suppression radius; 0 = from the model")
        .Unit("m")
        .Min(0);
    b.Field(&SweepOptions::max_poses, "max_poses", "refuse larger sweeps").Min(1);
    b.Field(&SweepOptions::refine, "refine", "refine the best grid poses by coordinate ascent");
    b.Field(&SweepOptions::refine_min_consistency, "refine_min_consistency", "grid poses refined above this")
        .Range(0, 1);
    b.Field(&SweepOptions::refine_min_confidence, "refine_min_confidence", "and above this confidence")
        .Range(0, 1);
    b.Field(&SweepOptions::refine_max_seeds, "refine_max_seeds", "grid poses refined at most").Min(0);
    b.Field(&SweepOptions::refine_min_step_m, "refine_min_step_m", "smallest refinement step")
        .Unit("m")
        .AboveZero();
    b.Field(&SweepOptions::refine_min_yaw_deg, "refine_min_yaw_deg", "smallest refinement yaw step")
        .Unit("deg")
        .AboveZero();
    b.Field(&SweepOptions::search, "search",
            "full: every grid pose; coarse-to-fine: skip blocks whose confidence bound cannot pass");
    b.Field(&SweepOptions::coarse_block, "coarse_block",
            "grid positions along x and y of the coarsest blocks (coarse-to-fine)")
        .Range(1, 4096);
    b.Check([](const SweepOptions& o) {
      if (o.x_max_m < o.x_min_m) throw OptionsFieldError("x_max_m", "is below x_min_m");
      if (o.y_max_m < o.y_min_m) throw OptionsFieldError("y_max_m", "is below y_min_m");
      if (o.yaws_deg.empty()) throw OptionsFieldError("yaws_deg", "must not be empty");
      const double positions = (std::floor((o.x_max_m - o.x_min_m) / o.step_m) + 1) *
                               (std::floor((o.y_max_m - o.y_min_m) / o.step_m) + 1);
      const double poses = positions * static_cast<double>(o.yaws_deg.size());
      if (poses > static_cast<double>(o.max_poses)) {
        throw OptionsFieldError("max_poses",
                                fmt::format("{} poses exceed it (coarser step, smaller ranges or "
                                            "fewer yaws)",
                                            poses));
      }
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<VerifyResult>() {
  static const StructInfo info = [] {
    // consistency and icp_cost_m are NaN when there is nothing to compare: JSON writes them as null.
    StructBuilder<VerifyResult> b("VerifyResult", "a verified pose (per-cell details are not JSON)");
    b.Field(&VerifyResult::consistency, "consistency", "share of comparable pairs that agree; null = none");
    b.Field(&VerifyResult::has_comparable_pairs, "has_comparable_pairs", "whether any pair was comparable");
    b.Field(&VerifyResult::comparable_pairs, "comparable_pairs", "scan point / model pairs compared");
    b.Field(&VerifyResult::consistent_pairs, "consistent_pairs", "of which consistent");
    b.Field(&VerifyResult::confidence, "confidence", "information of the model seen by the scans, [0, 1]");
    b.Field(&VerifyResult::icp_cost_m, "icp_cost_m", "trimmed ICP cost; null = no inlier pair").Unit("m");
    b.Field(&VerifyResult::inlier_fraction, "inlier_fraction", "inliers / scene points near the model");
    b.Field(&VerifyResult::icp_inliers, "icp_inliers", "ICP inlier pairs");
    b.Field(&VerifyResult::icp_candidates, "icp_candidates",
            "scene points in the model's grown bounding box");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanVerifyStats>() {
  static const StructInfo info = [] {
    StructBuilder<ScanVerifyStats> b("ScanVerifyStats",
                                     "one scan's share of a verified pose, as if it were alone");
    b.Field(&ScanVerifyStats::scan, "scan", "the scan's name");
    b.Field(&ScanVerifyStats::consistency, "consistency",
            "share of its comparable pairs that agree; null = none");
    b.Field(&ScanVerifyStats::comparable_pairs, "comparable_pairs",
            "its valid points whose ray meets the model");
    b.Field(&ScanVerifyStats::consistent_pairs, "consistent_pairs", "of which consistent");
    b.Field(&ScanVerifyStats::confidence, "confidence", "information of the model seen by this scan, [0, 1]");
    b.Field(&ScanVerifyStats::footprint_cells, "footprint_cells",
            "cells of the model's angular footprint visited")
        .Unit("cells");
    b.Field(&ScanVerifyStats::rays_cast, "rays_cast", "rays cast against the model");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<VerifyReport>() {
  static const StructInfo info = [] {
    StructBuilder<VerifyReport> b("VerifyReport",
                                  "lidarshop verify --json: VerifyResult's keys, per scan, the pose and the "
                                  "model");
    b.Flatten(&VerifyReport::result);
    b.Field(&VerifyReport::icp_cost, "icp_cost", "= icp_cost_m (older key)").Unit("m");
    b.Field(&VerifyReport::per_scan, "per_scan", "each scan's numbers, in the order of --scan");
    b.Field(&VerifyReport::world_from_model, "world_from_model",
            "the pose verified, 4 rows of 4 (model to world), rounded to 1e-9");
    b.Field(&VerifyReport::model_points, "model_points", "model points verified");
    b.Field(&VerifyReport::model_options, "model_options", "how the model points were made");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<Detection>() {
  static const StructInfo info = [] {
    StructBuilder<Detection> b("Detection", "a sweep's pose that passed both thresholds");
    b.Field(&Detection::comparable_pairs, "comparable_pairs", "scan point / model pairs compared");
    b.Field(&Detection::confidence, "confidence", "information of the model seen by the scans, [0, 1]");
    b.Field(&Detection::consistency, "consistency", "share of comparable pairs that agree");
    b.Field(&Detection::icp_cost_m, "icp_cost", "trimmed ICP cost; null = no inlier pair").Unit("m");
    b.Field(&Detection::inlier_fraction, "inlier_fraction", "inliers / scene points near the model");
    b.Field(&Detection::world_from_model, "world_from_model",
            "the pose, 4 rows of 4 (model to world); rounded to 1e-9 in a sweep's summary");
    b.Field(&Detection::x_m, "x_m", "world x of the model origin").Unit("m");
    b.Field(&Detection::y_m, "y_m", "world y of the model origin").Unit("m");
    b.Field(&Detection::yaw_deg, "yaw_deg", "yaw about +z").Unit("deg");
    b.Field(&Detection::z_m, "z_m", "world z of the model origin").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SweepThresholds>() {
  static const StructInfo info = [] {
    StructBuilder<SweepThresholds> b("SweepThresholds", "what a sweep's detections passed");
    b.Field(&SweepThresholds::min_comparable_pairs, "min_comparable_pairs",
            "at least this many comparable pairs");
    b.Field(&SweepThresholds::min_confidence, "min_confidence", "confidence above this");
    b.Field(&SweepThresholds::min_consistency, "min_consistency", "consistency above this");
    b.Field(&SweepThresholds::nms_radius_m, "nms_radius_m", "non-maximum suppression radius used").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SweepGridSummary>() {
  static const StructInfo info = [] {
    StructBuilder<SweepGridSummary> b("SweepGridSummary", "the grid a sweep covered and what it verified");
    b.Field(&SweepGridSummary::bound_evaluations, "bound_evaluations",
            "blocks whose confidence was bounded (coarse-to-fine)");
    b.Field(&SweepGridSummary::evaluated_poses, "evaluated_poses", "grid poses verified");
    b.Field(&SweepGridSummary::poses, "poses", "grid poses");
    b.Field(&SweepGridSummary::refine_evaluations, "refine_evaluations", "poses verified during refinement");
    b.Field(&SweepGridSummary::refined_seeds, "refined_seeds", "grid poses refined");
    b.Field(&SweepGridSummary::search, "search", "how the grid was searched");
    b.Field(&SweepGridSummary::x_count, "x_count", "grid positions along x");
    b.Field(&SweepGridSummary::y_count, "y_count", "grid positions along y");
    b.Field(&SweepGridSummary::yaws_deg, "yaws_deg", "yaws tried at every position").Unit("deg");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SweepSummary>() {
  static const StructInfo info = [] {
    StructBuilder<SweepSummary> b("SweepSummary", "a sweep's detections and grid (detections.json)");
    b.Field(&SweepSummary::detections, "detections", "by decreasing confidence");
    b.Field(&SweepSummary::grid, "grid", "the grid and how much of it was verified");
    b.Field(&SweepSummary::thresholds, "thresholds", "what the detections passed");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SweepReport>() {
  static const StructInfo info = [] {
    StructBuilder<SweepReport> b("SweepReport",
                                 "lidarshop sweep --json: SweepSummary's keys and both sides' options");
    b.Flatten(&SweepReport::summary);
    b.Field(&SweepReport::verify_options, "verify_options", "how the poses were verified");
    b.Field(&SweepReport::model_options, "model_options", "how the model points were made");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
