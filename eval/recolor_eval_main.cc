// recolor_eval: the evidence tables of bench/results/recolor.md. A synthetic scene
// (test_scenes::MakeRecolorScene) is scanned and photographed (scanner/photo.h) from cameras 1-3 m from the
// scanner; correspondences are drawn from scan points the camera sees, with noise and outliers; three
// resection methods recover the camera:
//   thesis  normalized DLT on every pair (no RANSAC, no refinement: the thesis's method)
//   ours    RANSAC DLT + Levenberg-Marquardt (recolor/resection.h)
//   pnp     OpenCV solvePnPRansac + solvePnPRefineLM given the TRUE intrinsics
// and the scan, its colours replaced by magenta, is recoloured with each camera and scored against the truth.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/recolor_eval.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/testing/street_scenes.h"
#include "lidarshop/util/atomic_file.h"

using namespace lidarshop;

namespace {

// Mean, 5th percentile (nearest rank) and worst of `values`; `worst_is_low`: the worst is the smallest.
std::string Distribution(std::vector<double> values, bool worst_is_low, int decimals) {
  std::sort(values.begin(), values.end());
  if (!worst_is_low) std::reverse(values.begin(), values.end());
  double mean = 0;
  for (double v : values) mean += v / values.size();
  const size_t p5 = static_cast<size_t>(std::max(1.0, std::ceil(0.05 * values.size()))) - 1;
  return fmt::format("{:.{}f} | {:.{}f} | {:.{}f}", mean, decimals, values[p5], decimals, values.front(),
                     decimals);
}

// One street seed drawn as both the table and the diagnosis use it: the scene (test_scenes::
// MakeStreetRecolorCase), its scan, the scan in magenta, the photo (`photo_samples` per pixel axis; 3:
// anti-aliased silhouettes, as a real photo's), the noisy pairs with their exact pixels, and the resection.
struct StreetDraw {
  test_scenes::StreetRecolorCase c;
  Scan truth, input;
  Photo photo;
  std::vector<PixelPointPair> exact;
  ResectionResult resection;
};

StreetDraw DrawStreet(int seed, double offset_m, int pair_count, double noise_px, double outliers,
                      int photo_samples) {
  StreetDraw d;
  d.c = test_scenes::MakeStreetRecolorCase(seed, offset_m);
  d.truth = test_scenes::ScanScene(d.c.scene);
  d.input = Clone(d.truth);
  d.input.color.setTo(cv::Scalar(250, 0, 250));
  PhotoOptions photo_options;
  photo_options.samples_per_axis = photo_samples;
  d.photo = RenderPhoto(d.c.scene, d.c.camera, photo_options);
  const std::vector<PixelPointPair> pairs = DrawCorrespondences(
      d.truth, d.c.camera, d.photo.depth_m, pair_count, noise_px, outliers, 1000 + seed, &d.exact);
  ResectionOptions options;
  options.width_px = d.c.camera.width_px;
  options.height_px = d.c.camera.height_px;
  options.seed = seed;
  d.resection = Resection(pairs, options);
  return d;
}

// The street scenes (test_scenes::MakeStreetRecolorCase, seeds 1..N): camera `offset_m` beside the scanner,
// `pairs` correspondences with noise and outliers, resected (ours), recoloured with the default options; per
// seed and the distribution (issue #30 class 3).
int RunStreet(int first_seed, int seeds, double offset_m, int pair_count, double noise_px, double outliers,
              bool per_seed, const RecolorOptions& recolor, int photo_samples) {
  std::vector<double> correct, wrong, unchanged, behind_unchanged, uncertain, true_correct, true_unchanged,
      true_behind_unchanged;
  int64_t changed_total = 0, hidden_total = 0, behind_changed_total = 0, behind_total = 0;
  fmt::print(
      "street scenes: camera {} m beside the scanner, {} pairs, {} px RMS noise, {:.0f} % outliers\n\n",
      offset_m, pair_count, noise_px, 100 * outliers);
  if (per_seed)
    fmt::print(
        "| seed | RMS on true pairs, px | visible correct, % | visible wrong colour, % | hidden changed (of) "
        "| "
        "behind an object: changed (of) | uncertain | true camera: visible correct, % | behind an "
        "object: changed |\n|---|---|---|---|---|---|---|---|---|\n");
  for (int seed = first_seed; seed < first_seed + seeds; ++seed) {
    const StreetDraw draw = DrawStreet(seed, offset_m, pair_count, noise_px, outliers, photo_samples);
    const test_scenes::StreetRecolorCase& c = draw.c;
    const Scan &truth = draw.truth, &input = draw.input;
    const Photo& photo = draw.photo;
    const std::vector<PixelPointPair>& exact = draw.exact;
    const ResectionResult& resection = draw.resection;
    const RecolorResult result = RecolorScan(input, photo.image, resection.camera, recolor);
    const RecolorScore score = ScoreRecolor(c.scene, truth, input, result.scan, c.camera);
    const RecolorResult true_result = RecolorScan(input, photo.image, c.camera, recolor);
    const RecolorScore true_score = ScoreRecolor(c.scene, truth, input, true_result.scan, c.camera);
    correct.push_back(score.visible_correct_percent());
    wrong.push_back(score.visible_wrong_percent());
    unchanged.push_back(100 - score.hidden_changed_percent());
    behind_unchanged.push_back(100 - score.hidden_behind_changed_percent());
    true_behind_unchanged.push_back(100 - true_score.hidden_behind_changed_percent());
    behind_changed_total += score.hidden_behind_changed;
    behind_total += score.hidden_behind;
    uncertain.push_back(static_cast<double>(result.uncertain));
    true_correct.push_back(true_score.visible_correct_percent());
    true_unchanged.push_back(100 - true_score.hidden_changed_percent());
    changed_total += score.hidden_changed;
    hidden_total += score.hidden;
    if (per_seed)
      fmt::print("| {} | {:.3f} | {:.2f} | {:.2f} | {} ({}) | {} ({}) | {} | {:.2f} | {} |\n", seed,
                 RmsReprojectionError(resection.camera, exact), score.visible_correct_percent(),
                 score.visible_wrong_percent(), score.hidden_changed, score.hidden,
                 score.hidden_behind_changed, score.hidden_behind, result.uncertain,
                 true_score.visible_correct_percent(), true_score.hidden_behind_changed);
  }
  fmt::print("\n| seeds {}..{} | mean | 5th percentile | worst |\n|---|---|---|---|\n", first_seed,
             first_seed + seeds - 1);
  fmt::print("| visible points correct, % (resected camera) | {} |\n", Distribution(correct, true, 2));
  fmt::print("| visible points that took a wrong colour, % (resected camera) | {} |\n",
             Distribution(wrong, false, 2));
  fmt::print("| hidden points unchanged, % (resected camera) | {} |\n", Distribution(unchanged, true, 3));
  fmt::print("| hidden behind another object (> 0.5 m): unchanged, % (resected camera) | {} |\n",
             Distribution(behind_unchanged, true, 3));
  fmt::print("| uncertain points kept (resected camera) | {} |\n", Distribution(uncertain, false, 0));
  fmt::print("| visible points correct, % (true camera) | {} |\n", Distribution(true_correct, true, 2));
  fmt::print("| hidden points unchanged, % (true camera) | {} |\n", Distribution(true_unchanged, true, 3));
  fmt::print("| hidden behind another object: unchanged, % (true camera) | {} |\n",
             Distribution(true_behind_unchanged, true, 3));
  fmt::print("\nhidden points changed over all seeds (resected camera): {} of {} ({:.3f} %)\n", changed_total,
             hidden_total, 100.0 * changed_total / std::max<int64_t>(1, hidden_total));
  fmt::print("hidden behind another object, changed over all seeds (resected camera): {} of {} ({:.3f} %)\n",
             behind_changed_total, behind_total,
             100.0 * behind_changed_total / std::max<int64_t>(1, behind_total));
  return 0;
}

// Where the errors of one street seed come from (for reading, not a table of the results page).
int DiagnoseStreet(int seed, double offset_m, int pair_count, double noise_px, double outliers,
                   bool true_camera, const RecolorOptions& recolor, int photo_samples,
                   const std::string& picture_path) {
  const StreetDraw draw = DrawStreet(seed, offset_m, pair_count, noise_px, outliers, photo_samples);
  const test_scenes::StreetRecolorCase& c = draw.c;
  const Scan &truth = draw.truth, &input = draw.input;
  const Photo& photo = draw.photo;
  const PinholeCamera camera = true_camera ? c.camera : draw.resection.camera;
  const RecolorResult result = RecolorScan(input, photo.image, camera, recolor);
  std::map<int, int64_t> cells_of_label;
  for (int r = 0; r < truth.rows; ++r)
    for (int col = 0; col < truth.cols; ++col)
      if (truth.valid.at<uint8_t>(r, col)) ++cells_of_label[truth.label.at<int32_t>(r, col)];
  for (const auto& [label, n] : cells_of_label)
    fmt::print("label {} ({}): {} cells\n", label, c.scene.objects[label].name, n);
  // Depth edges of the true photo: pixels whose 3x3 neighbourhood spans more than 20 % of their depth.
  cv::Mat dmax, dmin;
  cv::dilate(photo.depth_m, dmax, cv::Mat());
  cv::erode(photo.depth_m, dmin, cv::Mat());
  const Eigen::Vector3d center = c.camera.center_in_world();
  RaycastScene raycast;
  for (size_t i = 0; i < c.scene.objects.size(); ++i)
    raycast.AddMesh(MeshInWorld(c.scene.objects[i]), static_cast<int32_t>(i));
  raycast.Commit();
  int shown = 0;
  // The picture (grid, row 0 = top): grey hidden from the camera, white hidden but recoloured (a bleed), green
  // recoloured right, red recoloured wrong, yellow visible but kept as uncertain, blue visible but taken as
  // hidden; black outside the photo or no return.
  cv::Mat picture(truth.rows, truth.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  std::map<std::string, int> kinds;
  for (int r = 0; r < truth.rows; ++r) {
    for (int col = 0; col < truth.cols; ++col) {
      if (!truth.valid.at<uint8_t>(r, col)) continue;
      const Eigen::Vector3d world = WorldPointOfCell(truth, r, col);
      Eigen::Vector2d pixel;
      if (!ProjectWorldPoint(c.camera, world, &pixel) || !InsideImage(c.camera, pixel)) continue;
      const int pr = static_cast<int>(pixel.y()), pc = static_cast<int>(pixel.x());
      const double distance = (world - center).norm(), seen = photo.depth_m.at<float>(pr, pc);
      // Distance in pixels to the nearest pixel whose depth is more than 0.3 m nearer than the point.
      int edge_px = 99;
      for (int d = 0; d <= 8 && edge_px == 99; ++d)
        for (int dr = -d; dr <= d; ++dr)
          for (int dc = -d; dc <= d; ++dc) {
            const int rr = pr + dr, cc = pc + dc;
            if (rr < 0 || cc < 0 || rr >= photo.depth_m.rows || cc >= photo.depth_m.cols) continue;
            if (photo.depth_m.at<float>(rr, cc) < distance - 0.3) edge_px = std::min(edge_px, d);
          }
      Ray ray;
      ray.origin = center.cast<float>();
      ray.direction = (world - center).cast<float>();
      RayHit hit;
      raycast.CastSerial(std::span<const Ray>(&ray, 1), std::span<RayHit>(&hit, 1));
      const double gap = (1 - hit.t_hit) * distance;  // how far in front of the point the first hit lies
      const bool hidden = gap > 0.005;
      const bool changed = result.scan.color.at<cv::Vec3b>(r, col) != cv::Vec3b(250, 0, 250);
      const cv::Vec3b got = result.scan.color.at<cv::Vec3b>(r, col), want = truth.color.at<cv::Vec3b>(r, col);
      bool close = true;
      for (int k = 0; k < 3; ++k) close = close && std::abs(got[k] - want[k]) <= 10;
      std::string kind;
      if (hidden && changed) {
        const int occluder = photo.label.at<int32_t>(pr, pc);
        const int first = hit.geometry_id;
        kind = fmt::format(
            "hidden changed: first hit {} (own {}) {} in front, seen by the scanner: {}, edge {} px", first,
            truth.label.at<int32_t>(r, col),
            gap < 0.1 ? "< 0.1 m"
            : gap < 1 ? "0.1-1 m"
                      : "> 1 m",
            cells_of_label.count(first) ? "yes" : "no", edge_px > 4 ? 5 : edge_px);
        (void)occluder;
        if (shown++ < 15 || (occluder == 0 && shown < 1000 && shown % 50 == 0))
          fmt::print("cell {} {} label {} at {:.2f} m, occluder {} at {:.2f} m, edge {} px, got {} {} {}\n",
                     r, col, truth.label.at<int32_t>(r, col), distance, occluder, seen, edge_px, got[0],
                     got[1], got[2]);
      } else if (!hidden && !close) {
        kind = fmt::format("visible wrong: {}, edge {} px, label {}",
                           changed                                     ? "recoloured"
                           : result.uncertain_mask.at<uint8_t>(r, col) ? "kept, uncertain"
                                                                       : "kept, hidden to us",
                           edge_px > 4 ? 5 : edge_px, truth.label.at<int32_t>(r, col));
      }
      if (!kind.empty()) ++kinds[kind];
      cv::Vec3b& shade = picture.at<cv::Vec3b>(r, col);
      if (hidden)
        shade = changed ? cv::Vec3b(255, 255, 255) : cv::Vec3b(90, 90, 90);
      else if (changed)
        shade = close ? cv::Vec3b(40, 170, 40) : cv::Vec3b(230, 30, 30);
      else
        shade = result.uncertain_mask.at<uint8_t>(r, col) ? cv::Vec3b(240, 220, 0) : cv::Vec3b(40, 80, 240);
    }
  }
  for (const auto& [kind, n] : kinds) fmt::print("{:6d}  {}\n", n, kind);
  if (!picture_path.empty()) {
    cv::Mat bgr;
    cv::cvtColor(picture, bgr, cv::COLOR_RGB2BGR);
    WritePathAtomically(picture_path, [&](const std::string& path) { return CvImWrite(path, bgr); });
    fmt::print("wrote {}\n", picture_path);
  }
  return 0;
}

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
  int street = 0, street_pairs = 32;
  double street_offset_m = 2.0;
  app.add_option("--street", street,
                 "instead: the random street scenes, seeds 1..N (test_scenes::MakeStreetRecolorCase)");
  int street_first = 1;
  app.add_option("--street-first", street_first,
                 "street scenes: the first seed (--street N runs N seeds from it)")
      ->check(CLI::PositiveNumber);
  app.add_option("--street-offset", street_offset_m, "street scenes: camera distance from the scanner, m");
  app.add_option("--street-pairs", street_pairs, "street scenes: correspondences per seed");
  int diagnose = 0;
  bool diagnose_true = false;
  app.add_option("--diagnose", diagnose, "street scenes: where the errors of this seed come from");
  app.add_flag("--diagnose-true-camera", diagnose_true, "--diagnose with the true camera");
  std::string diagnose_picture;
  app.add_option(
      "--diagnose-picture", diagnose_picture,
      "--diagnose: a PNG on the scan's grid (green right, red wrong, yellow uncertain, blue visible "
      "but taken as hidden, grey hidden, white hidden but recoloured)");
  RecolorOptions street_options;
  int photo_samples = 3;
  app.add_option(
         "--photo-samples", photo_samples,
         "street scenes: the photo's samples per pixel axis (3: anti-aliased like a real photo; 1: one "
         "ray per pixel centre)")
      ->check(CLI::Range(1, 8));
  bool no_guard = false;
  app.add_flag("--no-edge-guard", no_guard, "street scenes: recolour without the edge guard (before #30)");
  app.add_option("--camera-uncertainty", street_options.camera_uncertainty_px,
                 "street scenes: RecolorOptions::camera_uncertainty_px");
  app.add_option("--skirt-depth", street_options.skirt_depth_m,
                 "street scenes: RecolorOptions::skirt_depth_m");
  app.add_option("--skirt-depth-per-width", street_options.skirt_depth_per_width,
                 "street scenes: RecolorOptions::skirt_depth_per_width (0: every wall skirt_depth_m deep)");
  app.add_option("--max-blend-levels", street_options.max_blend_levels,
                 "street scenes: RecolorOptions::max_blend_levels (255: always bilinear)");
  CLI11_PARSE(app, argc, argv);
  street_options.edge_guard = !no_guard;
  if (diagnose > 0)
    return DiagnoseStreet(diagnose, street_offset_m, street_pairs, noise_px, outliers, diagnose_true,
                          street_options, photo_samples, diagnose_picture);
  if (street > 0)
    return RunStreet(street_first, street, street_offset_m, street_pairs, noise_px, outliers, per_draw,
                     street_options, photo_samples);

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
    // Visibility with the true camera: the default (skirts with walls, 1 px margin, edge guard) and its parts without
    // the guard, the literal segment test, and the visibility test before the skirts (2 px margin).
    struct Variant {
      const char* name;
      VisibilityMethod method;
      bool skirts;
      double depth_m;
      int margin_px;
      bool edge_guard = false;  // the variants show the visibility test alone; the default has the guard
    };
    const Variant variants[] = {
        {"true camera, z-buffer + skirts (0.25 m walls) + 1 px margin + edge guard (default)",
         VisibilityMethod::kZBuffer, true, 0.25, 1, true},
        {"true camera, z-buffer + skirts (0.25 m walls) + 1 px margin (the default before the edge guard)",
         VisibilityMethod::kZBuffer, true, 0.25, 1},
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
      options.edge_guard = variant.edge_guard;
      const RecolorResult result = RecolorScan(s.input, s.photo.image, s.camera, options);
      const RecolorScore score = ScoreRecolor(s.scene, s.truth, s.input, result.scan, s.camera);
      fmt::print("| {:.0f} m | - | {} | 0 | {:.2f} | {:.3f} ({} of {} points) |\n", offset, variant.name,
                 score.visible_correct_percent(), score.hidden_changed_percent(), score.hidden_changed,
                 score.hidden);
    }
  }
  return 0;
}
