// Automatic resection (issue 32 item 4): the camera of a photo from the scan alone, without hand-picked pairs.
//
//   1. Working resolution. The photo is reduced (never enlarged) so that one of its pixels covers about one
//      scan cell seen from the scanner (`pixels_per_cell`): a rendering of the scan has no finer detail, and
//      SIFT compares like with like. Intrinsics: the given ones, or each horizontal field of view of
//      `fov_candidates_deg` (square pixels, principal point at the centre, no distortion).
//   2. Search. The scan's colour (grey; its intensity when it has no colour) is rendered as the camera would
//      see it from the scanner centre: `view_azimuths` directions around the scanner's z axis at each of
//      `view_elevations_deg`, every view with the photo's focal length on a canvas 1.5 x the photo (so a photo
//      pointing anywhere falls inside a view). Rendering splats each scan point as a square of its footprint
//      (cell angle x range, seen from the camera) into a z-buffer; every pixel keeps the index of the point it
//      shows (the "point map"). SIFT (OpenCV) on the photo and the view, matched by Lowe's ratio test: a
//      match is a pair (photo pixel, the view's point). Per view, OpenCV's solvePnPRansac (EPnP minimal sets,
//      fixed seed); the view and field of view with the most inliers win (the next `search_candidates` - 1
//      are tried in turn when the rounds from it find no supported camera). With a rough pose
//      (`AutoResection(..., rough)`) only that view is rendered.
//   3. Rounds. The scan is rendered again from the estimated camera with the photo's intrinsics and size: the
//      parallax and the change of viewpoint (a camera metres from the scanner) are gone, so the rendering and
//      the photo differ by a few pixels. SIFT features are matched only within `guided_radius_px` of the same
//      place (ratio test among those), and each pair is made sub-pixel: the point shown at the view's
//      keypoint projects at p', not at the keypoint k; the photo's pixel is moved by p' - k. PnP RANSAC, then
//      Levenberg–Marquardt on the inliers (solvePnPRefineLM; with unknown intrinsics a golden-section search
//      over the focal length around it), inliers re-selected. Rounds stop when the camera moves less than
//      0.5 mm and 0.001°, or after `rounds`.
//   4. The answer is refused (InputError naming the photo, with the numbers) when fewer than `min_inliers`
//      pairs or a share below `min_inlier_share` agree, their RMS exceeds `max_rms_px`, or the last round still
//      moved the camera 1 cm or 0.05° (it has not settled: a repeating texture pulls it over): a wrong camera
//      would recolour the scan with the wrong photo pixels without a sign.
//   5. Check. Guided SIFT and patches look only near the estimate, so a repeating texture (bricks) matched one
//      period over is a consistent answer. The scan is rendered from the final camera and SIFT matched with the
//      ratio test over the whole rendering (a repeating feature has a second match as good and drops out);
//      PnP RANSAC on those pairs alone gives a second camera. When it explains at least 12 of them and 1.5 x as
//      many as the final camera, the camera is ambiguous: the rounds restart from the second camera (twice at
//      most), else the photo is refused ("ambiguous").
//   6. Silhouettes (silhouette_alignment.h): with a rough pose and known intrinsics, a photo refused by
//      steps 1-5 is aligned by the scan's outlines and intensity instead — a photo from the far side of the
//      objects (pumpA's) shows their backs, which share no features with the scanner's side. Refused as well
//      when the outlines do not land on the photo's edges. The result says method "silhouettes" and warns.
// Deterministic: keypoints are sorted before their descriptors are computed, the brute-force matcher gives
// the same answer on any thread count, RANSAC is seeded.
// Thresholds are in working pixels (about one scan cell); the camera and `rms_px` are in the photo's pixels.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct AutoResectionOptions {
  // Horizontal fields of view tried when the intrinsics are not given, degrees.
  std::vector<double> fov_candidates_deg = {45, 60, 75, 90};
  int view_azimuths = 8;  // search views around the scanner's z axis (360° / this apart)
  std::vector<double> view_elevations_deg = {0};  // elevations of the search views, degrees
  double pixels_per_cell = 1.0;  // working resolution: photo pixels per scan cell (seen from the scanner)
  int features = 4000;           // SIFT features per image at most
  double ratio = 0.8;            // Lowe's ratio test: best / second-best descriptor distance below this
  // Search cameras tried in turn (most inliers first) while the rounds from them give no supported camera.
  int search_candidates = 3;
  int rounds = 8;                // re-render, re-match, re-solve at most this many times
  double guided_radius_px = 12;  // rounds: a photo feature matches view features this near only, working px
  // Rounds also match patches of the rendering in the photo (normalized cross-correlation, sub-pixel peak):
  // dense pairs where SIFT finds few. 0 = off.
  int patch_px = 15;                 // patch side, working pixels (odd)
  int patch_step_px = 10;            // patch centres this far apart, working pixels
  double min_patch_score = 0.8;      // correlation of a found patch at least this
  double ransac_threshold_px = 2.0;  // inlier reprojection error, working pixels
  int ransac_iterations = 3000;      // PnP RANSAC's minimal sets at most
  int min_inliers = 40;              // fewer agreeing pairs: refused
  double min_inlier_share = 0.25;    // inliers / pairs of the last round below this: refused
  double max_rms_px = 1.5;           // inliers' RMS above this (working pixels): refused
  uint64_t seed = 1;                 // RANSAC's random sets
  // Step 6: with a rough pose and known intrinsics, when no feature camera is supported, align the scan's
  // outlines and intensity to the photo instead (silhouette_alignment.h).
  bool silhouettes = true;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<AutoResectionOptions>();

struct AutoResectionResult {
  std::string method = "features";    // or "silhouettes" (step 6)
  PinholeCamera camera;               // in the photo's pixels
  std::vector<PixelPointPair> pairs;  // the last round's pairs (photo pixels, world points)
  std::vector<uint8_t> inlier;        // per pair: 1 = inlier
  int inliers = 0;
  double inlier_share = 0;    // inliers / pairs
  double rms_px = 0;          // RMS reprojection error of the inliers, photo pixels
  double rms_work_px = 0;     // the same in working pixels (what max_rms_px bounds)
  double work_scale = 1;      // working pixels per photo pixel (<= 1)
  double search_fov_deg = 0;  // field of view of the winning search (0 with given intrinsics)
  int search_view = -1;       // the winning search view (-1 with a rough camera)
  int search_inliers = 0;     // its PnP inliers
  int rounds = 0;             // rounds run
  double last_move_m = 0;     // how far the last round moved the camera centre, metres
  double last_turn_deg = 0;   // and turned it, degrees
  // The independent check (step 5): SIFT pairs ratio-tested over the whole rendering from the final camera,
  // how many, how many it explains within ransac_threshold_px, and their median error (working pixels).
  int check_pairs = 0;
  int check_agree = 0;
  double check_median_work_px = 0;
  int check_alt_inliers = 0;
  double check_alt_move_m = 0;
  // Step 6 only: the share of the scan's outlines on a photo edge and the mutual information (nats).
  double silhouette_edge_share = 0;
  double silhouette_mutual_information = 0;
  std::string trace;                  // what the search candidate's rounds did (refusals quote it)
  std::vector<std::string> warnings;  // one sentence each
  std::string Summary() const;        // one line
};

// An automatic resection in brief: the result of `lidarshop resection --auto --json` (and recolor --auto's
// "auto_resection"), in its order. Described.
struct AutoResectionSummary {
  std::string method;  // AutoResectionResult::method: "features" or "silhouettes"
  int inliers = 0;
  int64_t pairs = 0;  // the last round's pairs
  double inlier_share = 0, rms_px = 0, rms_work_px = 0, work_scale = 1;
  int rounds = 0, search_view = -1, search_inliers = 0;
  std::optional<double> search_fov_deg;  // with searched intrinsics only (not given ones)
  int check_pairs = 0, check_agree = 0, check_alt_inliers = 0;
  // Method "silhouettes" only.
  std::optional<double> silhouette_edge_share, silhouette_mutual_information;
  std::vector<double> focal_px;       // fx, fy, pixels
  std::vector<double> camera_center;  // x, y, z in the world frame, metres
  std::vector<std::string> warnings;
  // The options it ran with, where a command nests it in its own result (recolor --auto); empty elsewhere.
  std::optional<AutoResectionOptions> options;
};
AutoResectionSummary SummarizeAutoResection(const AutoResectionResult& result);
template <>
const StructInfo& InfoOf<AutoResectionSummary>();

// The camera of `photo` (CV_8UC3 RGB or CV_8UC1) from `scan` (colour or intensity, world_from_scanner).
// `intrinsics`: known intrinsics and distortion (its pose and size are ignored; it is scaled to the photo's
// size if its width differs); none = searched (see above). `rough_world_from_camera`: start there instead of
// searching from the scanner centre. Throws InputError (naming `what`) when the scan has neither colour nor
// intensity, or no camera is supported (step 4).
AutoResectionResult AutoResection(
    const Scan& scan, const cv::Mat& photo, const AutoResectionOptions& options,
    const std::optional<PinholeCamera>& intrinsics = std::nullopt,
    const std::optional<Eigen::Matrix4d>& rough_world_from_camera = std::nullopt,
    const std::string& what = "photo");

}  // namespace lidarshop
