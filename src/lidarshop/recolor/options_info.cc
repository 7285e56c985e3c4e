// Descriptions of the recolouring options and enums (util/options.h).
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<VisibilityMethod>() {
  static const EnumInfo info = MakeEnumInfo<VisibilityMethod>(
      "visibility method",
      {{VisibilityMethod::kZBuffer, "zbuffer", "z-buffer of the scan mesh seen by the camera"},
       {VisibilityMethod::kSegment, "segment", "ray-cast the segment from the camera to each point"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PairKind>() {
  static const EnumInfo info = MakeEnumInfo<PairKind>(
      "correspondence kind", {{PairKind::kPixelPoint, "pixel-point", "photo pixel <-> scan point or cell"},
                              {PairKind::kLandmark, "landmark", "3-D point <-> 3-D point"},
                              {PairKind::kPixelPixel, "pixel-pixel", "pixel <-> pixel of two images"}});
  return info;
}

template <>
const StructInfo& InfoOf<ResectionOptions>() {
  static const StructInfo info = [] {
    StructBuilder<ResectionOptions> b("ResectionOptions", "the camera of a photo from pixel <-> point pairs");
    b.Field(&ResectionOptions::width_px, "width_px", "the photo's width").Unit("px").Min(0);
    b.Field(&ResectionOptions::height_px, "height_px", "the photo's height").Unit("px").Min(0);
    b.Field(&ResectionOptions::ransac_threshold_px, "ransac_threshold_px", "inlier reprojection error")
        .Unit("px")
        .AboveZero();
    b.Field(&ResectionOptions::ransac_iterations, "ransac_iterations", "minimal sets tried at most").Min(1);
    b.Field(&ResectionOptions::ransac_min_iterations, "ransac_min_iterations", "minimal sets tried at least")
        .Min(1);
    b.Field(&ResectionOptions::local_optimization, "local_optimization",
            "refit every set with as many inliers as the best (or a lower MSAC score) on them (DLT + LM), "
            "score it "
            "after (LO-RANSAC); then trade inliers for the pairs just outside the threshold while the score "
            "drops");
    b.Field(&ResectionOptions::ransac_confidence, "ransac_confidence",
            "stop once a better set is this unlikely")
        .AboveZero()
        .Below(1);
    b.Field(&ResectionOptions::seed, "seed", "seed of RANSAC's random sets");
    b.Field(&ResectionOptions::refine, "refine", "refine the DLT camera by Levenberg-Marquardt");
    b.Field(&ResectionOptions::square_pixels, "square_pixels", "one focal length (fx = fy)");
    b.Field(&ResectionOptions::max_aspect_deviation, "max_aspect_deviation",
            "RANSAC skips cameras whose |fx/fy - 1| or skew/fx exceeds this")
        .AboveZero();
    b.Field(&ResectionOptions::refine_skew, "refine_skew", "refine the skew");
    b.Field(&ResectionOptions::radial_coefficients, "radial_coefficients", "radial distortion terms refined")
        .Range(0, 3);
    b.Field(&ResectionOptions::refine_tangential, "refine_tangential", "refine p1, p2");
    b.Field(&ResectionOptions::min_inliers_for_distortion, "min_inliers_for_distortion",
            "distortion is refined only with this many inliers")
        .Min(6);
    b.Field(&ResectionOptions::min_inliers_for_principal_point, "min_inliers_for_principal_point",
            "below this many inliers the principal point stays at the photo's centre")
        .Min(0);
    b.Field(&ResectionOptions::degenerate_ratio, "degenerate_ratio",
            "coplanar / collinear below this spread ratio")
        .AboveZero()
        .Below(1);
    // The photo size is required when resecting, but a fresh struct (before the photo is known) is valid.
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorOptions> b("RecolorOptions", "occlusion-aware recolouring");
    b.Field(&RecolorOptions::visibility, "visibility", "how hidden points are found");
    b.Field(&RecolorOptions::depth_tolerance_m, "depth_tolerance_m",
            "a surface this close in front does not hide")
        .Unit("m")
        .Min(0);
    b.Field(&RecolorOptions::relative_depth_tolerance, "relative_depth_tolerance",
            "fraction of the camera distance added to the tolerance")
        .Min(0)
        .Below(1);
    b.Field(&RecolorOptions::silhouette_margin_px, "silhouette_margin_px", "z-buffer window radius")
        .Unit("px")
        .Range(0, 50);
    b.Field(&RecolorOptions::silhouette_skirts, "silhouette_skirts",
            "grow every occluder of the scan mesh by one scan cell");
    b.Field(&RecolorOptions::skirt_depth_m, "skirt_depth_m", "skirt walls behind each occluder edge")
        .Unit("m")
        .Min(0);
    b.Field(&RecolorOptions::skirt_depth_per_width, "skirt_depth_per_width",
            "skirt walls no deeper than this times the occluder's width where the scan saw it whole (0 = no "
            "limit)")
        .Min(0);
    b.Field(&RecolorOptions::edge_guard, "edge_guard",
            "keep points near an occluding depth edge in the photo (uncertain) instead of recolouring them");
    b.Field(&RecolorOptions::camera_uncertainty_px, "camera_uncertainty_px",
            "how far the camera may put a point from its true pixel (edge guard margin, plus one scan step)")
        .Unit("px")
        .Min(0)
        .Max(100);
    b.Field(&RecolorOptions::edge_min_jump_m, "edge_min_jump_m",
            "a nearer surface is an occluding edge when this much (plus the tolerances) in front")
        .Unit("m")
        .Min(0);
    b.Field(&RecolorOptions::max_blend_levels, "max_blend_levels",
            "blend the photo pixels around a projection only when they differ by at most this much (else the "
            "nearest one's colour); 255 = always bilinear")
        .Unit("levels")
        .Range(0, 255);
    b.Field(&RecolorOptions::zbuffer_scale, "zbuffer_scale", "z-buffer size / photo size").AboveZero().Max(1);
    b.Field(&RecolorOptions::max_range_jump_ratio, "max_range_jump_ratio", "scan mesh edge rule").AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<AutoResectionOptions>() {
  static const StructInfo info = [] {
    StructBuilder<AutoResectionOptions> b(
        "AutoResectionOptions",
        "the camera of a photo from the scan alone (rendered views, SIFT, PnP RANSAC)");
    b.Field(&AutoResectionOptions::fov_candidates_deg, "fov_candidates_deg",
            "horizontal fields of view tried when the intrinsics are not given")
        .Unit("deg")
        .Range(1, 179);
    b.Field(&AutoResectionOptions::view_azimuths, "view_azimuths", "search views around the scanner's z axis")
        .Range(1, 72);
    b.Field(&AutoResectionOptions::view_elevations_deg, "view_elevations_deg",
            "elevations of the search views")
        .Unit("deg")
        .Range(-80, 80);
    b.Field(&AutoResectionOptions::pixels_per_cell, "pixels_per_cell",
            "working resolution: photo pixels per scan cell seen from the scanner")
        .AboveZero()
        .Max(8);
    b.Field(&AutoResectionOptions::features, "features", "SIFT features per image at most").Min(50);
    b.Field(&AutoResectionOptions::ratio, "ratio",
            "Lowe's ratio test: best / second-best distance below this")
        .AboveZero()
        .Max(1);
    b.Field(&AutoResectionOptions::search_candidates, "search_candidates",
            "search cameras tried in turn (most inliers first) while none gives a supported camera")
        .Range(1, 1000);
    b.Field(&AutoResectionOptions::rounds, "rounds", "re-render, re-match, re-solve at most this many times")
        .Min(0);
    b.Field(&AutoResectionOptions::guided_radius_px, "guided_radius_px",
            "rounds: a photo feature matches rendered features this near only")
        .Unit("px")
        .AboveZero();
    b.Field(&AutoResectionOptions::patch_px, "patch_px",
            "rounds: side of the rendered patches found in the photo by correlation (0 = off)")
        .Unit("px")
        .Range(0, 63);
    b.Field(&AutoResectionOptions::patch_step_px, "patch_step_px", "patch centres this far apart")
        .Unit("px")
        .Range(1, 1000);
    b.Field(&AutoResectionOptions::min_patch_score, "min_patch_score",
            "normalized cross-correlation of a found patch at least this")
        .Range(-1, 1);
    b.Field(&AutoResectionOptions::ransac_threshold_px, "ransac_threshold_px",
            "inlier reprojection error (working pixels)")
        .Unit("px")
        .AboveZero();
    b.Field(&AutoResectionOptions::ransac_iterations, "ransac_iterations",
            "PnP RANSAC's minimal sets at most")
        .Min(1);
    b.Field(&AutoResectionOptions::min_inliers, "min_inliers", "fewer agreeing pairs: refused").Min(6);
    b.Field(&AutoResectionOptions::min_inlier_share, "min_inlier_share",
            "inliers / pairs below this: refused")
        .Range(0, 1);
    b.Field(&AutoResectionOptions::max_rms_px, "max_rms_px",
            "inliers' RMS above this (working pixels): refused")
        .Unit("px")
        .AboveZero();
    b.Field(&AutoResectionOptions::seed, "seed", "seed of RANSAC's random sets");
    b.Field(&AutoResectionOptions::silhouettes, "silhouettes",
            "with a rough pose and known intrinsics, when no feature camera is supported: align the scan's "
            "outlines and intensity to the photo instead (recolor/silhouette_alignment.h)");
    return b.Build();
  }();
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PhotoModel>() {
  static const EnumInfo info = MakeEnumInfo<PhotoModel>(
      "photo pair model", {{PhotoModel::kHomography, "homography", "b = H a (a plane, or a camera turning)"},
                           {PhotoModel::kFundamental, "fundamental", "b^T F a = 0 (any scene)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<LandmarkModel>() {
  static const EnumInfo info = MakeEnumInfo<LandmarkModel>(
      "landmark model",
      {{LandmarkModel::kRigid, "rigid", "rotation and translation"},
       {LandmarkModel::kSimilarity, "similarity", "rotation, translation and a uniform scale"}});
  return info;
}

template <>
const StructInfo& InfoOf<AlignOptions>() {
  static const StructInfo info = [] {
    StructBuilder<AlignOptions> b("AlignOptions", "transforms from correspondences");
    b.Field(&AlignOptions::scale, "scale", "landmarks: allow a uniform scale (similarity)");
    b.Field(&AlignOptions::model, "model", "photo pairs: the model fitted");
    b.Field(&AlignOptions::threshold_px, "threshold_px", "photo pairs: RANSAC inlier threshold")
        .Unit("px")
        .AboveZero()
        .Max(1000);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LandmarkAlignment>() {
  static const StructInfo info = [] {
    StructBuilder<LandmarkAlignment> b("LandmarkAlignment", "a transform from scan <-> scan landmarks");
    b.Field(&LandmarkAlignment::model, "model", "what was fitted");
    b.Field(&LandmarkAlignment::scale, "scale", "the uniform scale (1 for a rigid transform)");
    b.Field(&LandmarkAlignment::rms_m, "rms_m", "root mean square of the residuals").Unit("m");
    b.Field(&LandmarkAlignment::residual_m, "residual_m", "per pair: |T source - target|").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotoPairModel>() {
  static const StructInfo info = [] {
    StructBuilder<PhotoPairModel> b("PhotoPairModel",
                                    "a homography or fundamental matrix between two photos");
    b.Field(&PhotoPairModel::model, "model", "what was fitted");
    b.Field(&PhotoPairModel::rms_px, "rms_px", "root mean square of the inliers' errors").Unit("px");
    b.Field(&PhotoPairModel::error_px, "error_px",
            "per pair: |H a - b|, or the distance of b to the epipolar line F a")
        .Unit("px");
    b.Field(&PhotoPairModel::inlier, "inlier", "per pair: 1 = a RANSAC inlier, 0 = an outlier");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ResectionPairError>() {
  static const StructInfo info = [] {
    StructBuilder<ResectionPairError> b("ResectionPairError", "one pair of a resection");
    b.Field(&ResectionPairError::error_px, "error_px", "reprojection error with the final camera").Unit("px");
    b.Field(&ResectionPairError::inlier, "inlier", "RANSAC kept the pair");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ResectionSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ResectionSummary> b("ResectionSummary", "a photo's camera from its pairs, in brief");
    b.Field(&ResectionSummary::inliers, "inliers", "pairs RANSAC kept");
    b.Field(&ResectionSummary::pairs, "pairs", "pairs given");
    b.Field(&ResectionSummary::rms_px, "rms_px", "RMS reprojection error of the inliers, final camera")
        .Unit("px");
    b.Field(&ResectionSummary::dlt_rms_px, "dlt_rms_px", "the same with the DLT camera (before refinement)")
        .Unit("px");
    b.Field(&ResectionSummary::ransac_sets, "ransac_sets", "RANSAC's minimal sets tried");
    b.Field(&ResectionSummary::focal_px, "focal_px", "focal lengths fx, fy").Unit("px");
    b.Field(&ResectionSummary::principal_point_px, "principal_point_px", "principal point cx, cy").Unit("px");
    b.Field(&ResectionSummary::k1, "k1", "first radial distortion coefficient");
    b.Field(&ResectionSummary::camera_center, "camera_center", "the camera centre x, y, z in the world frame")
        .Unit("m");
    b.Field(&ResectionSummary::per_pair, "per_pair", "every pair's error, in the pairs' order");
    b.Field(&ResectionSummary::warnings, "warnings", "what looks wrong, one sentence each");
    b.Field(&ResectionSummary::options, "options",
            "the options, where a command's result nests the resection");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<AutoResectionSummary>() {
  static const StructInfo info = [] {
    using S = AutoResectionSummary;
    StructBuilder<S> b("AutoResectionSummary", "a photo's camera found from the scan alone, in brief");
    b.Field(&S::method, "method", "\"features\" (SIFT, PnP RANSAC) or \"silhouettes\" (the fallback)");
    b.Field(&S::inliers, "inliers", "the last round's pairs that agree with the camera");
    b.Field(&S::pairs, "pairs", "the last round's pairs");
    b.Field(&S::inlier_share, "inlier_share", "inliers / pairs");
    b.Field(&S::rms_px, "rms_px", "RMS reprojection error of the inliers, photo pixels").Unit("px");
    b.Field(&S::rms_work_px, "rms_work_px", "the same in working pixels").Unit("px");
    b.Field(&S::work_scale, "work_scale", "working pixels per photo pixel");
    b.Field(&S::rounds, "rounds", "re-render, re-match, re-solve rounds run");
    b.Field(&S::search_view, "search_view", "the winning search view (-1 with a rough camera)");
    b.Field(&S::search_inliers, "search_inliers", "its PnP inliers");
    b.Field(&S::search_fov_deg, "search_fov_deg", "field of view of the winning search (searched intrinsics)")
        .Unit("deg");
    b.Field(&S::check_pairs, "check_pairs", "independent check: SIFT pairs over the final rendering");
    b.Field(&S::check_agree, "check_agree", "of those, the pairs the camera explains");
    b.Field(&S::check_alt_inliers, "check_alt_inliers", "inliers of the best other camera of the check");
    b.Field(&S::silhouette_edge_share, "silhouette_edge_share",
            "silhouettes: share of the scan's outlines on a photo edge");
    b.Field(&S::silhouette_mutual_information, "silhouette_mutual_information",
            "silhouettes: mutual information of scan and photo")
        .Unit("nats");
    b.Field(&S::focal_px, "focal_px", "focal lengths fx, fy").Unit("px");
    b.Field(&S::camera_center, "camera_center", "the camera centre x, y, z in the world frame").Unit("m");
    b.Field(&S::warnings, "warnings", "what looks wrong, one sentence each");
    b.Field(&S::options, "options", "the options, where a command's result nests the resection");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorSummary>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorSummary> b("RecolorSummary", "a recolouring from one photo, in brief");
    b.Field(&RecolorSummary::returns, "returns", "valid cells").Unit("cells");
    b.Field(&RecolorSummary::recolored, "recolored", "valid cells that took the photo's colour")
        .Unit("cells");
    b.Field(&RecolorSummary::outside_image, "outside_image", "behind the camera or outside the photo")
        .Unit("cells");
    b.Field(&RecolorSummary::hidden, "hidden", "inside the photo but occluded").Unit("cells");
    b.Field(&RecolorSummary::uncertain, "uncertain", "seen, but kept near an occluding edge").Unit("cells");
    b.Field(&RecolorSummary::edge_margin_px, "edge_margin_px", "the edge guard's margin (0: no guard)")
        .Unit("px");
    b.Field(&RecolorSummary::disagreement, "disagreement",
            "share of the recoloured points whose photo colour disagrees with their own (when measurable)");
    b.Field(&RecolorSummary::warnings, "warnings",
            "the resection's, then the recolouring's, one sentence each");
    b.Field(&RecolorSummary::resection, "resection", "the camera's resection (--correspondences)");
    b.Field(&RecolorSummary::auto_resection, "auto_resection", "the camera's automatic resection (--auto)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorPhotoUsed>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorPhotoUsed> b("RecolorPhotoUsed", "a photo that coloured a scan");
    b.Field(&RecolorPhotoUsed::index, "index", "its images2D index, or its --photo's position");
    b.Field(&RecolorPhotoUsed::name, "name", "the images2D entry's name, or the photo's path");
    b.Field(&RecolorPhotoUsed::model, "model", "the camera model");
    b.Field(&RecolorPhotoUsed::gain, "gain", "R, G, B exposure gain relative to photo 0");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorPhotoSkipped>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorPhotoSkipped> b("RecolorPhotoSkipped", "an images2D entry left out of a colouring");
    b.Field(&RecolorPhotoSkipped::index, "index", "its images2D index");
    b.Field(&RecolorPhotoSkipped::name, "name", "its name");
    b.Field(&RecolorPhotoSkipped::why, "why", "why it cannot colour the scan");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotosRecolorSeconds>() {
  static const StructInfo info = [] {
    using S = PhotosRecolorSeconds;
    StructBuilder<S> b("PhotosRecolorSeconds", "wall clock per phase of a colouring from several photos");
    b.Field(&S::read, "read", "reading and decoding the scan file (and its photos)").Unit("s");
    b.Field(&S::colour, "colour", "the colouring as a whole (the phases below but write)").Unit("s");
    b.Field(&S::write, "write", "writing the outputs").Unit("s");
    b.Field(&S::scene, "scene", "the occlusion scene: scan mesh and skirts").Unit("s");
    b.Field(&S::visibility, "visibility", "every photo's visibility and samples").Unit("s");
    b.Field(&S::zbuffer, "zbuffer", "of visibility: the z-buffers").Unit("s");
    b.Field(&S::projection, "projection", "of visibility: the cells projected and tested").Unit("s");
    b.Field(&S::choice, "choice", "each cell's photo chosen").Unit("s");
    b.Field(&S::gains, "gains", "the exposure gains fitted").Unit("s");
    b.Field(&S::colours, "colours", "the corrected colours").Unit("s");
    b.Field(&S::blend, "blend", "the seam blending").Unit("s");
    b.Field(&S::output, "output", "the output scan made").Unit("s");
    b.Field(&S::colour_cpu, "colour_cpu", "the process's CPU time during the colouring, every thread")
        .Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotosRecolorSummary>() {
  static const StructInfo info = [] {
    using S = PhotosRecolorSummary;
    StructBuilder<S> b("PhotosRecolorSummary", "a recolouring from several photos (a station's), in brief");
    b.Field(&S::returns, "returns", "valid cells").Unit("cells");
    b.Field(&S::coloured, "coloured", "valid cells some photo saw").Unit("cells");
    b.Field(&S::constraints, "constraints", "overlap pairs used to fit the gains");
    b.Field(&S::seam_edges, "seam_edges", "neighbouring coloured cells coloured by different photos");
    b.Field(&S::blended, "blended", "cells solved again by the seam blending").Unit("cells");
    b.Field(&S::photos, "photos", "the photos that coloured the scan, in order");
    b.Field(&S::skipped, "skipped", "images2D entries left out, and why");
    b.Field(&S::seconds, "seconds", "wall clock per phase");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
