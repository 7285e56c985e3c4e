// Scoring a recoloured synthetic scan against the truth (tests, bench/results/recolor.md): which scan points
// the camera really sees (segments cast against the true scene, not the scan mesh), and whether visible
// points got the true colour while hidden ones kept theirs.
#pragma once

#include <cstdint>
#include <string>

#include <vector>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scene.h"

namespace lidarshop {

struct RecolorScore {
  int64_t visible = 0;            // valid points inside the photo that the camera sees (true scene)
  int64_t visible_recolored = 0;  // ... that took a photo colour
  int64_t visible_correct = 0;    // ... whose colour is now within `max_level_difference` of the truth
  int64_t visible_wrong = 0;      // ... that took a photo colour further than that from the truth
  int64_t hidden = 0;             // valid points inside the photo hidden from the camera by the true scene
  int64_t hidden_changed = 0;     // ... whose colour changed (must be 0)
  // Of the hidden points, those whose first surface towards the camera lies more than
  // `behind_object_m` in front of them (behind another object, not a fold of their own surface: the bleed
  // of issue #30), and of those the ones whose colour changed.
  int64_t hidden_behind = 0;
  int64_t hidden_behind_changed = 0;
  int64_t outside = 0;  // behind the camera or outside the photo
  double visible_correct_percent() const { return visible ? 100.0 * visible_correct / visible : 0.0; }
  double hidden_changed_percent() const { return hidden ? 100.0 * hidden_changed / hidden : 0.0; }
  double visible_wrong_percent() const { return visible ? 100.0 * visible_wrong / visible : 0.0; }
  double hidden_behind_changed_percent() const {
    return hidden_behind ? 100.0 * hidden_behind_changed / hidden_behind : 0.0;
  }
  std::string Summary() const;
};

// `truth` holds the true colours (the synthetic scanner's), `input` the colours before recolouring and
// `output` after (all the same grid). A point is hidden when the segment from the camera to it meets the true
// scene more than `visibility_tolerance_m` before the point.
RecolorScore ScoreRecolor(const SceneDescription& scene, const Scan& truth, const Scan& input,
                          const Scan& output, const PinholeCamera& camera, int max_level_difference = 10,
                          double visibility_tolerance_m = 0.005, double behind_object_m = 0.5);

// `count` correspondences of scan points the camera sees (a user clicks points seen in both): a valid cell
// drawn at random whose projection lies inside the photo and whose distance from the camera matches the
// photo's depth there (within 2 cm). Pixels get Gaussian noise of RMS length `noise_px` (σ = noise / √2 per
// axis); the first round(outlier_fraction · count) pairs are moved 20–200 px in a random direction.
// `exact` (optional) receives the noise-free pairs. Deterministic in `seed`.
std::vector<PixelPointPair> DrawCorrespondences(const Scan& scan, const PinholeCamera& camera,
                                                const cv::Mat& photo_depth_m, int count, double noise_px,
                                                double outlier_fraction, uint64_t seed,
                                                std::vector<PixelPointPair>* exact = nullptr);

// The evaluation's camera (bench/results/recolor.md): `offset_m` beside and a little behind the scanner at
// (0, 0, 1.5) — along (0.8, −0.6, 0.05) — looking at (0, 10, 1), 800 x 600 px, 70° horizontal field.
PinholeCamera EvaluationCamera(double offset_m);

// RMS reprojection error of `pairs` with `camera`, pixels (a point behind the camera counts 10^6 px).
double RmsReprojectionError(const PinholeCamera& camera, const std::vector<PixelPointPair>& pairs);

struct PhotosRecolorResult;

// Scoring a station coloured from its own photos (recolor/station_recolor.h) against the truth colours of a
// synthetic scan (the photos render the scanner's colours at photo 0's exposure; issue 32 item 5).
struct StationColourScore {
  int64_t returns = 0;    // valid cells
  int64_t coloured = 0;   // ... that some photo coloured
  double mean_error = 0;  // RGB units (mean absolute difference over R, G, B), over the coloured cells
  double p95_error = 0;   // its 95th percentile
  // Colour steps (mean absolute RGB difference) between 4-neighbour coloured cells: across a seam (the two
  // cells coloured by different photos) and across the other neighbours; visibility = seam / ordinary.
  int64_t seam_edges = 0;
  double seam_step = 0, ordinary_step = 0;
  double seam_visibility() const { return ordinary_step > 0 ? seam_step / ordinary_step : 0; }
  double uncoloured_share() const { return returns ? 1.0 - static_cast<double>(coloured) / returns : 0; }
};
StationColourScore ScoreStationColours(const Scan& truth, const PhotosRecolorResult& result);

}  // namespace lidarshop
