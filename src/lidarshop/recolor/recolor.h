// Occlusion-aware recolouring of a scan from a photo (thesis 3.2.2.1).
//
// A scan point takes the photo's colour (bilinear at its projection, over the pixels at its depth) only when
//   1. it lies in front of the camera and projects inside the photo, and
//   2. the camera sees it: the segment from the point to the camera centre meets no other surface of the
//      scan.
// Otherwise it keeps its own colour. (The thesis's tool let occluded points take the occluder's colour from
// the photo; here they never change.)
//
// Visibility is decided against the scan's own grid mesh (scan/scan_mesh.h, world frame, edges across
// depth jumps dropped) with Embree: one ray per photo pixel (or per pixel of a reduced "z-buffer",
// `zbuffer_scale`) from the camera centre gives the distance to the first surface of the scan seen through
// that pixel. A point at distance d from the camera is hidden when that first surface is nearer than
// d − tolerance, which is the segment test of the thesis with the segment's end moved `tolerance` off the
// point's own surface (tolerance = depth_tolerance_m + relative_depth_tolerance · d). Safety margins:
//   - silhouette skirts (`silhouette_skirts`, recolor/silhouette_skirt.h): the scan mesh stops at the last
//     cell of an object, up to one scan step (angular spacing × the object's range) short of its true
//     silhouette; the skirt grows every occluder by exactly that step, and walls `skirt_depth_m` deep behind
//     the edge stand for the occluder's sides that the scanner never saw. Without them, points just behind an
//     occluder's edge see the camera through the gap and take the occluder's colour (bench/results/recolor.md
//     measures it).
//   - `silhouette_margin_px`: the first-surface distance is the minimum over a (2m + 1)² window of z-buffer
//     pixels: the z-buffer samples the mesh at pixel centres, a point may project up to 0.71 px away.
//   - the window's own depth slope: on surfaces seen at a grazing angle the window minimum is nearer than the
//     point by (margin · slope); that much is added to the tolerance, with the slope taken one-sided (the
//     smaller of the forward and backward differences), so that a depth jump does not count as slope.
// A point is also hidden when the first surface at its pixel turns its back to the camera: the scan mesh
// faces the scanner, so the camera then sees the side of that surface the scanner never saw (a camera facing
// the scanner across an object sees the object's other side, whose colour is not the scanned side's).
// Near an occluding edge the z-buffer cannot be trusted: the camera's pose is known only to a pixel or so
// (a resection's reprojection error), and an occluder's true silhouette lies anywhere within one scan step of
// its scan mesh. A point the test above lets through is *uncertain* (`edge_guard`) when a surface at least
// `edge_min_jump_m` + the tolerance nearer than the point lies within `edge_margin` z-buffer pixels of its
// projection, with edge_margin = camera_uncertainty_px + the scan's angular step in photo pixels (step × fx):
// it keeps its colour, is counted in `uncertain` and flagged in `RecolorResult::uncertain_mask`. (Issue #30:
// with a camera resected from 32 noisy pairs, 1.1 % of the hidden points 1.4–4.4 m behind an object, within
// 4 px of its silhouette, took the object's colour or a blend; bench/results/recolor.md, "street scenes".)
// The colour of a recoloured point is bilinear over the photo's pixels whose z-buffer distance agrees with
// the point's (within the tolerance and the local slope), so no blend is taken across a depth edge; when no
// neighbour agrees, the nearest pixel's colour. Nor across a colour edge: when those pixels differ by more than
// `max_blend_levels` in a channel, the point takes the colour of the one nearest its projection, since a blend
// of a window frame and its wall is a colour neither surface has (on the street scenes of issue #30, 0.6 % of
// the visible points took such a blend; bench/results/recolor.md).
// `VisibilityMethod::kSegment` instead casts the exact segment of every point (Embree occlusion rays, no
// pixel margin; skirts when `silhouette_skirts`): without skirts, the literal thesis test.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class VisibilityMethod { kZBuffer, kSegment };
template <>
const EnumInfo& EnumInfoOf<VisibilityMethod>();

struct RecolorOptions {
  VisibilityMethod visibility = VisibilityMethod::kZBuffer;
  double depth_tolerance_m = 0.03;  // metres: a surface this close in front of a point does not hide it
  double relative_depth_tolerance = 0.01;  // fraction of the camera distance added to the tolerance
  // z-buffer window radius (z-buffer pixels), 0 = no margin: the z-buffer samples the scan mesh at pixel
  // centres, a point's projection lies up to 0.71 px from its pixel's centre; 1 covers that sampling.
  int silhouette_margin_px = 1;
  // Grow every occluder of the scan mesh by one scan cell at its own range (recolor/silhouette_skirt.h): the
  // scan's own angular spacing decides how far a silhouette may reach, not a photo-pixel margin.
  bool silhouette_skirts = true;
  // Skirt walls this far behind each occluder's edge, metres (0 = caps only): faces the scanner never saw
  // (an occluder's sides inside its shadow) that a camera beside the scanner looks at. A prior on how deep
  // occluders are, which no scan can measure: with the 3 m camera of bench/results/recolor.md, caps alone
  // let 29 hidden points past the 0.5 m deep pillar's unseen side, 0.25 m walls none (at 0.14 % of the
  // visible points). The walls also stand for whole objects in the scanner's shadow (a post behind a post),
  // which the camera sees and the scan does not: on 100 random street scenes 0.25 m walls let 0.37 % of the
  // points behind another object take a colour, 2 m walls 0.04 %, for 1.3 points fewer visible points right
  // (bench/results/recolor.md, "Colour edges, thin occluders' walls"). A wall never reaches past the farther
  // return beside it.
  double skirt_depth_m = 2.0;
  // ... but no deeper than this × the occluder's width where the scan saw it whole (recolor/silhouette_skirt.h;
  // 0 = always skirt_depth_m). 1 sees the façade beside a thin post, but lets a post the scanner did not see
  // behind a thin one bleed (the same 100 scenes: 0.30 % of the points behind objects changed with 2 m walls).
  double skirt_depth_per_width = 0.0;
  // Keep points near an occluding depth edge (above): they are `uncertain`, not recoloured. z-buffer only.
  bool edge_guard = true;
  // How far (photo pixels) the camera may put a point from its true pixel: the pose's uncertainty. For a
  // resected camera about twice its reprojection RMS on the inliers (`lidarshop recolor --correspondences`
  // uses the larger of this and 2 × the RMS). Part of the edge guard's margin.
  double camera_uncertainty_px = 1.0;
  // A nearer surface counts as an occluding edge when it is this much (plus the depth tolerance and the local
  // slope) in front of the point, metres: smaller steps (a kerb, a window recess) do not hide a point.
  double edge_min_jump_m = 0.2;
  // Photo levels (0-255, per channel): the pixels around a projection are blended only when they differ by at
  // most this much; otherwise the nearest one's colour (above). 255 = always bilinear.
  int max_blend_levels = 24;
  double zbuffer_scale = 1.0;         // z-buffer size / photo size, (0, 1]; 0.5 = a quarter of the rays
  double max_range_jump_ratio = 0.1;  // scan mesh edges (scan/scan_mesh.h)
  void Check() const;                 // throws OptionsError
};
template <>
const StructInfo& InfoOf<RecolorOptions>();

struct RecolorResult {
  Scan scan;  // a clone of the input with `color` replaced where recolored (created, grey from intensity,
              // or black without intensity, when the input had no colour)
  cv::Mat recolored;       // CV_8U rows x cols: 255 = the point took the photo's colour
  cv::Mat uncertain_mask;  // CV_8U rows x cols: 255 = seen, but kept near an occluding edge (`uncertain`)
  int64_t returns = 0;     // valid cells
  int64_t recolored_count = 0;  // valid cells that took the photo's colour
  int64_t outside_image = 0;    // behind the camera or projected outside the photo
  int64_t hidden = 0;           // inside the photo but occluded by another surface of the scan
  int64_t uncertain = 0;        // not hidden, but too near an occluding edge in the photo to trust: kept
  double edge_margin_px = 0;    // the edge guard's margin, photo pixels (0: no guard)
  // Of the recoloured points, the fraction whose photo colour disagrees with the scan's own colour (or, without
  // colour, its intensity): their ranks (brightness quantiles among the recoloured points) differ by more than
  // kRecolorRankGap. Independent values disagree on 1 − (1 − gap)² of the points; NaN when nothing was
  // recoloured or the scan had neither colour nor intensity.
  double disagreement = 0;
  // What looks wrong, one sentence each (most points disagree: the camera is probably wrong); empty if nothing.
  std::vector<std::string> warnings;
  std::string Summary() const;  // one line
};

// Two brightness ranks (quantiles in [0, 1]) further apart than this disagree (dimensionless).
inline constexpr double kRecolorRankGap = 0.25;
// A recolouring where more than this fraction of the points disagree is reported (dimensionless). Independent
// values give 1 − (1 − 0.25)² = 0.56; a right camera agrees on most points.
inline constexpr double kRecolorDisagreementLimit = 0.5;

// The fraction of the points of `recolored` (CV_8U, non-zero = recoloured) whose brightness in `after` (RGB)
// and in `before` (its colour, else its intensity) differ in rank by more than kRecolorRankGap; NaN when no
// point is recoloured or `before` has neither colour nor intensity. At most `max_points` points are compared
// (evenly spread), enough for a fraction.
double RecolorDisagreement(const Scan& before, const cv::Mat& after_color, const cv::Mat& recolored,
                           int64_t max_points = 200000);

// A recolouring from one photo in brief: the result of `lidarshop recolor --json` (one photo), in its order.
// Described.
struct RecolorSummary {
  int64_t returns = 0, recolored = 0, outside_image = 0, hidden = 0, uncertain = 0;  // RecolorResult's counts
  double edge_margin_px = 0;
  std::optional<double> disagreement;  // RecolorResult::disagreement when it is a number
  // The resection's warnings (when the camera came from one), then the recolouring's.
  std::vector<std::string> warnings;
  // How the camera was found, when the command found it: from pairs, or automatically.
  std::optional<ResectionSummary> resection;
  std::optional<AutoResectionSummary> auto_resection;
};
RecolorSummary SummarizeRecolor(const RecolorResult& result,
                                const std::optional<ResectionSummary>& resection = std::nullopt,
                                const std::optional<AutoResectionSummary>& auto_resection = std::nullopt);
template <>
const StructInfo& InfoOf<RecolorSummary>();

// `photo` is CV_8UC3 RGB of the camera's size (camera.width_px x camera.height_px), else InputError.
RecolorResult RecolorScan(const Scan& scan, const cv::Mat& photo, const PinholeCamera& camera,
                          const RecolorOptions& options = {});

// The photo's colour at a continuous pixel position (geometry/camera.h convention), bilinear, edges clamped;
// the nearest pixel's colour when the four differ by more than `max_blend_levels` in a channel (a colour edge).
cv::Vec3b SamplePhoto(const cv::Mat& photo, const Eigen::Vector2d& pixel_px, int max_blend_levels = 255);

}  // namespace lidarshop
