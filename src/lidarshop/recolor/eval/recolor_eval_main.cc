// recolor_eval: the evidence tables of bench/results/recolor.md. A synthetic scene
// (test_scenes::MakeRecolorScene) is scanned and photographed (scanner/photo.h) from cameras 1-3 m from the
// scanner; correspondences are drawn from scan points the camera sees, with noise and outliers; three
// resection methods recover the camera:
//   thesis  normalized DLT on every pair (no RANSAC, no refinement: the thesis's method)
//   ours    RANSAC DLT + Levenberg-Marquardt (recolor/resection.h)
//   pnp     OpenCV solvePnPRansac + solvePnPRefineLM given the TRUE intrinsics
// and the scan, its colours replaced by magenta, is recoloured with each camera and scored against the truth.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/recolor_eval.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"

using namespace lidarshop;

namespace {

struct Setup {
  SceneDescription scene;
  Scan truth, input;
  PinholeCamera camera;
  Photo photo;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"recolor_eval: resection and recolouring against synthetic truth (bench/results/recolor.md)"};
  int seeds = 5;
  double noise_px = 0.5, outliers = 0.2;
  bool resection_only = false, per_draw = false;
  app.add_option("--seeds,--draws", seeds, "draws per configuration (seeds 1..N)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--resection-only", resection_only,
               "only the RMS on true pairs: no recolouring, no true-camera rows (fast, for many draws)");
  app.add_flag("--per-draw", per_draw,
               "also print every draw of \"ours\" (offset, pairs, seed, inliers, RMS)");
  app.add_option("--noise", noise_px, "RMS pixel noise of the correspondences");
  app.add_option("--outliers", outliers, "fraction of outlier pairs");
  CLI11_PARSE(app, argc, argv);

  fmt::print(
      "noise {} px RMS (σ = {:.3f} px per axis), {:.0f} % outliers, {} draws per row (mean; worst in "
      "brackets)\n\n",
      noise_px, noise_px / std::sqrt(2.0), 100 * outliers, seeds);
  fmt::print(
      "| camera offset | pairs | method | RMS on true pairs, px | visible points correct, % | hidden points "
      "changed, % |\n|---|---|---|---|---|---|\n");
  for (double offset : {1.0, 2.0, 3.0}) {
    Setup s;
    s.scene = test_scenes::MakeRecolorScene();
    s.truth = test_scenes::ScanScene(s.scene);
    s.input = Clone(s.truth);
    s.input.color.setTo(cv::Scalar(250, 0, 250));
    s.camera = EvaluationCamera(offset);
    s.photo = RenderPhoto(s.scene, s.camera);
    for (int count : {10, 20, 40}) {
      const char* names[] = {"thesis DLT", "ours (RANSAC + LM)", "OpenCV PnP, true K"};
      for (int method = 0; method < 3; ++method) {
        double rms_sum = 0, rms_worst = 0, correct_sum = 0, correct_worst = 100, hidden_sum = 0,
               hidden_worst = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
          std::vector<PixelPointPair> exact;
          const std::vector<PixelPointPair> pairs = DrawCorrespondences(
              s.truth, s.camera, s.photo.depth_m, count, noise_px, outliers, 100 * seed + count, &exact);
          ResectionOptions options;
          options.width_px = s.camera.width_px;
          options.height_px = s.camera.height_px;
          options.seed = seed;
          PinholeCamera camera;
          std::string
              inlier_flags;  // "ours": 1 = inlier, per pair (the first round(outliers · count) are outliers)
          if (method == 0) {
            camera = CameraFromProjection(NormalizedDlt(pairs), options.width_px, options.height_px);
          } else if (method == 1) {
            const ResectionResult result = Resection(pairs, options);
            camera = result.camera;
            for (uint8_t inlier : result.inlier) inlier_flags += inlier ? '1' : '0';
          } else {
            camera = ResectWithIntrinsics(pairs, s.camera, options).camera;
          }
          const double rms = RmsReprojectionError(camera, exact);
          rms_sum += rms;
          rms_worst = std::max(rms_worst, rms);
          if (per_draw && method == 1)
            fmt::print("  draw: {:.0f} m, {} pairs, seed {}: inliers {}, RMS on true pairs {:.3f} px\n",
                       offset, count, seed, inlier_flags, rms);
          if (resection_only) continue;
          const RecolorScore score = ScoreRecolor(s.scene, s.truth, s.input,
                                                  RecolorScan(s.input, s.photo.image, camera).scan, s.camera);
          correct_sum += score.visible_correct_percent();
          correct_worst = std::min(correct_worst, score.visible_correct_percent());
          hidden_sum += score.hidden_changed_percent();
          hidden_worst = std::max(hidden_worst, score.hidden_changed_percent());
        }
        if (resection_only) {
          fmt::print("| {:.0f} m | {} | {} | {:.3f} ({:.3f}) | - | - |\n", offset, count, names[method],
                     rms_sum / seeds, rms_worst);
          continue;
        }
        fmt::print("| {:.0f} m | {} | {} | {:.3f} ({:.3f}) | {:.2f} ({:.2f}) | {:.3f} ({:.3f}) |\n", offset,
                   count, names[method], rms_sum / seeds, rms_worst, correct_sum / seeds, correct_worst,
                   hidden_sum / seeds, hidden_worst);
      }
    }
    if (resection_only) continue;
    // Visibility with the true camera: the default (skirts with walls, 1 px margin) and its parts, the literal
    // segment test, and the visibility test before the skirts (2 px margin).
    struct Variant {
      const char* name;
      VisibilityMethod method;
      bool skirts;
      double depth_m;
      int margin_px;
    };
    const Variant variants[] = {
        {"true camera, z-buffer + skirts (0.25 m walls) + 1 px margin (default)", VisibilityMethod::kZBuffer,
         true, 0.25, 1},
        {"true camera, z-buffer + skirt caps only (no walls) + 1 px margin", VisibilityMethod::kZBuffer, true,
         0.0, 1},
        {"true camera, z-buffer + skirts (0.25 m walls), no margin", VisibilityMethod::kZBuffer, true, 0.25,
         0},
        {"true camera, segment test + skirts (0.25 m walls)", VisibilityMethod::kSegment, true, 0.25, 0},
        {"true camera, literal segment test (no skirts)", VisibilityMethod::kSegment, false, 0.0, 0},
        {"true camera, z-buffer + 2 px margin, no skirts (the previous default)", VisibilityMethod::kZBuffer,
         false, 0.0, 2},
        {"true camera, z-buffer, no skirts, no margin", VisibilityMethod::kZBuffer, false, 0.0, 0},
    };
    for (const Variant& variant : variants) {
      RecolorOptions options;
      options.visibility = variant.method;
      options.silhouette_skirts = variant.skirts;
      options.skirt_depth_m = variant.depth_m;
      options.silhouette_margin_px = variant.margin_px;
      const RecolorResult result = RecolorScan(s.input, s.photo.image, s.camera, options);
      const RecolorScore score = ScoreRecolor(s.scene, s.truth, s.input, result.scan, s.camera);
      fmt::print("| {:.0f} m | - | {} | 0 | {:.2f} | {:.3f} ({} of {} points) |\n", offset, variant.name,
                 score.visible_correct_percent(), score.hidden_changed_percent(), score.hidden_changed,
                 score.hidden);
    }
  }
  return 0;
}
