// segment_eval: quality of the two-step segmentation against its baselines on the synthetic evaluation set.
//
//   segment_eval [--scenes DIR] [--seeds N] [--model histogram|gmm|both] [--markdown FILE]
//   segment_eval --random-seeds 1..100 [--markdown FILE] [--dump DIR]
//
// Every data/segment_eval/*.json scene is scanned with the synthetic scanner (scanner/scanner.h); the target
// object is label 1. For each stroke seed, one short stroke inside the eroded object and one in the
// background are drawn (MakeEvalStrokes) and every method runs on the same strokes. Prints per-scene IoU and
// the mean IoU, precision and recall of every method; with --markdown, writes the tables there too.
//
// --random-seeds: instead, the random scenes of those seeds (scanner/random_scene.h, 400 x 300 cells), the
// target their target_label; one stroke on the target's upper part and one on the background below it
// (EvalStrokeOptions::upper_and_below, stroke seed 7919 · seed + 1); the two-step cut and grabCut on the same
// strokes. Prints a row per seed and the distribution (mean, 5th percentile, worst seed); --dump writes the
// pictures of the three worst seeds.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/scanner/random_scene.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment_eval.h"
#include "lidarshop/testing/random_eval.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/timer.h"

using namespace lidarshop;

namespace {

// Step 1 with the inferred background and the final cut; the truth and grabCut; the two-step errors (missed
// object cells red, extra cells blue).
cv::Mat Panel(const Scan& scan, const cv::Mat& truth, const cv::Mat& strokes, const SegmentOptions& options,
              int grabcut_iterations) {
  SegmentOptions o = options;
  o.method = SegmentMethod::kTwoStep;
  const SegmentResult r = SegmentObject(scan, strokes, o);
  cv::Mat step1 = SegmentOverlay(scan, r.step1_mask, strokes);
  step1.setTo(cv::Scalar(255, 0, 255), r.inferred_background);
  cv::Mat row1, row2;
  cv::hconcat(step1, SegmentOverlay(scan, r.mask, strokes), row1);
  cv::hconcat(SegmentOverlay(scan, truth, strokes),
              SegmentOverlay(scan, GrabCutFromStrokes(scan, strokes, grabcut_iterations), strokes), row2);
  cv::Mat errors(scan.rows, scan.cols, CV_8UC3, cv::Scalar(60, 60, 60));
  errors.setTo(cv::Scalar(200, 200, 200), truth & r.mask);
  errors.setTo(cv::Scalar(255, 0, 0), truth & ~r.mask);
  errors.setTo(cv::Scalar(0, 80, 255), r.mask & ~truth & (scan.valid != 0));
  cv::Mat row3;
  cv::resize(errors, row3, row1.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat both;
  cv::vconcat(std::vector<cv::Mat>{row1, row2, row3}, both);
  return both;
}

// A random scene of the evaluation: its scan, the target's cells and the two automatic strokes (seeded from
// the scene's seed); `strokes` empty when the target leaves no room for them.
struct RandomCase {
  SceneDescription scene;
  Scan scan;
  cv::Mat truth, strokes;
};
RandomCase MakeRandomCase(uint64_t seed, const RandomSceneOptions& scene_options) {
  RandomCase c;
  c.scene = RandomScene(seed, scene_options);
  c.scan = SynthesizeScan(c.scene);
  c.truth = (c.scan.label == c.scene.target_label) & (c.scan.valid != 0);
  EvalStrokeOptions stroke_options;
  stroke_options.upper_and_below = true;
  try {
    c.strokes = MakeEvalStrokes(c.truth, c.scan.valid, seed * 7919 + 1, stroke_options);
  } catch (const InputError&) {
  }
  return c;
}

int RunRandom(const std::vector<uint64_t>& seeds, const RandomSceneOptions& scene_options,
              const SegmentOptions& options, int grabcut_iterations, const std::string& dump_dir,
              const std::string& markdown_path) {
  test_scenes::EvalReport report;
  auto emit = [&](const std::string& text) { report.Emit(text); };
  emit(fmt::format(
      "\n### Random scenes: seeds {}..{} ({} x {} cells; strokes on the target's upper part and the "
      "background below it; * = the target coloured like its background)\n\n| seed | target | distance m | "
      "target cells | two-step IoU | grabCut IoU | two-step s |\n"
      "|---|---|---|---|---|---|---|\n",
      seeds.front(), seeds.back(), scene_options.columns, scene_options.rows));
  std::vector<double> two_step, grabcut;
  std::vector<bool> like_background;
  std::vector<uint64_t> scored;
  std::vector<uint64_t> no_room;
  double seconds = 0;
  for (uint64_t seed : seeds) {
    const RandomCase random_case = MakeRandomCase(seed, scene_options);
    const SceneDescription& scene = random_case.scene;
    const Scan& scan = random_case.scan;
    const cv::Mat& truth = random_case.truth;
    const cv::Mat& strokes = random_case.strokes;
    if (strokes.empty()) {
      no_room.push_back(seed);
      emit(fmt::format("| {} | {} | {:.1f} | {} | no room for strokes | | |\n", seed,
                       test_scenes::TargetColumn(scene), test_scenes::TargetDistance(scene),
                       cv::countNonZero(truth)));
      continue;
    }
    SegmentOptions o = options;
    o.method = SegmentMethod::kTwoStep;
    Timer timer;
    const SegmentResult result = SegmentObject(scan, strokes, o);
    const double s = timer.Seconds();
    seconds += s;
    const double iou = ScoreMask(result.mask, truth, scan.valid).iou;
    const double grabcut_iou =
        grabcut_iterations > 0
            ? ScoreMask(GrabCutFromStrokes(scan, strokes, grabcut_iterations), truth, scan.valid).iou
            : 0.0;
    two_step.push_back(iou);
    grabcut.push_back(grabcut_iou);
    scored.push_back(seed);
    like_background.push_back(test_scenes::TargetColouredLikeBackground(scene));
    emit(fmt::format("| {} | {} | {:.1f} | {} | {:.3f} | {:.3f} | {:.2f} |\n", seed,
                     test_scenes::TargetColumn(scene), test_scenes::TargetDistance(scene),
                     cv::countNonZero(truth), iou, grabcut_iou, s));
  }
  if (scored.empty()) {
    fmt::print(stderr, "segment_eval: no random scene had room for strokes\n");
    return 1;
  }
  emit("\n| method | mean IoU | 5th percentile | worst IoU (seed) | scenes |\n|---|---|---|---|---|\n");
  for (const auto& [name, values] :
       {std::pair<std::string, const std::vector<double>*>{"two-step", &two_step}, {"grabcut", &grabcut}}) {
    if (name == "grabcut" && grabcut_iterations == 0) continue;
    const test_scenes::SeedDistribution d = test_scenes::Distribute(*values, scored, true);
    emit(fmt::format("| {} | {:.3f} | {:.3f} | {:.3f} ({}) | {} |\n", name, d.mean, d.p5, d.worst,
                     d.worst_seed, values->size()));
  }
  int better = 0;
  for (size_t i = 0; i < scored.size(); ++i) better += grabcut[i] > two_step[i] + 0.01;
  emit(
      fmt::format("\nTwo-step total {:.1f} s. Scenes where grabCut beats two-step by more than 0.01 IoU: {} "
                  "of {}. Scenes "
                  "without room for strokes: {}.\n",
                  seconds, better, scored.size(),
                  no_room.empty() ? "none" : fmt::format("{}", fmt::join(no_room, ", "))));
  emit(fmt::format(
      "Targets coloured like their background (*): two-step {}, grabCut {}. The others: two-step {}, grabCut "
      "{}.\n",
      test_scenes::MeanWhere(two_step, like_background, true),
      test_scenes::MeanWhere(grabcut, like_background, true),
      test_scenes::MeanWhere(two_step, like_background, false),
      test_scenes::MeanWhere(grabcut, like_background, false)));
  if (!dump_dir.empty()) {
    for (size_t i : test_scenes::WorstIndices(two_step, 3, true)) {
      const RandomCase worst = MakeRandomCase(scored[i], scene_options);  // scored: it had room for strokes
      WriteImage(fmt::format("{}/random_{}.png", dump_dir, scored[i]),
                 Panel(worst.scan, worst.truth, worst.strokes, options, grabcut_iterations));
    }
  }
  report.Write(markdown_path);
  return 0;
}

// The windowed two-step cut (SegmentOptions::window_margin_cells) against the whole-scan cut
// (window_margin_cells = 0), per scene and stroke seed.
struct WindowComparison {
  int runs = 0, differing = 0, grown = 0;
  int64_t differing_cells = 0;
  double window_fraction = 0;  // sum over runs of window cells / scan cells
  double seconds_window = 0, seconds_whole = 0;
  std::vector<std::string> which;  // the runs whose masks differ

  void Add(const std::string& name, const Scan& scan, const cv::Mat& strokes, const SegmentOptions& options) {
    SegmentOptions windowed = options, whole = options;
    windowed.method = whole.method = SegmentMethod::kTwoStep;
    whole.window_margin_cells = 0;
    Timer timer;
    const SegmentResult a = SegmentObject(scan, strokes, windowed);
    seconds_window += timer.Seconds();
    timer.Restart();
    const SegmentResult b = SegmentObject(scan, strokes, whole);
    seconds_whole += timer.Seconds();
    ++runs;
    grown += a.window_growths > 0;
    window_fraction += static_cast<double>(a.window_rows) * a.window_cols / (double(scan.rows) * scan.cols);
    const int cells = cv::countNonZero(a.mask != b.mask);
    if (cells > 0) {
      ++differing;
      differing_cells += cells;
      which.push_back(fmt::format("{} ({} cells of {})", name, cells, cv::countNonZero(b.mask)));
    }
  }
  std::string Report(const std::string& what) const {
    return fmt::format(
        "{}: the windowed two-step mask differs from the whole-scan one in {} of {} runs ({} cells in "
        "all){}; "
        "mean window {:.1f} % of the scan, grown in {} runs; {:.1f} s windowed, {:.1f} s whole scan\n",
        what, differing, runs, differing_cells,
        which.empty() ? "" : fmt::format(": {}", fmt::join(which, ", ")),
        runs > 0 ? 100.0 * window_fraction / runs : 0.0, grown, seconds_window, seconds_whole);
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Segmentation quality on the synthetic evaluation set (two-step vs baselines)"};
  std::string scenes_dir = LIDARSHOP_SOURCE_DIR "/data/segment_eval";
  std::string model = "both", markdown_path;
  int seeds = 3, grabcut_iterations = 5;
  SegmentOptions options;
  app.add_option("--scenes", scenes_dir, "folder of scene JSON files (target = label 1)");
  app.add_option("--seeds", seeds, "stroke seeds per scene")->capture_default_str();
  app.add_option("--model", model, "histogram | gmm | both")->capture_default_str();
  app.add_option("--grabcut-iterations", grabcut_iterations, "0 = skip grabCut")->capture_default_str();
  app.add_option("--markdown", markdown_path, "also write the tables to this file");
  std::string random_seeds;
  RandomSceneOptions scene_options;
  app.add_option("--random-seeds", random_seeds,
                 "instead of --scenes: the random scenes of these seeds (A..B, or N = 1..N; "
                 "scanner/random_scene.h), two-step against grabCut, the distribution over the seeds");
  app.add_option("--random-columns", scene_options.columns, "random scenes: columns")->capture_default_str();
  app.add_option("--random-rows", scene_options.rows, "random scenes: rows")->capture_default_str();
  // Tuning knobs (the defaults are SegmentOptions').
  app.add_option("--depth-smoothness", options.depth_step.smoothness);
  app.add_option("--depth-bias", options.depth_step.foreground_bias);
  app.add_option("--depth-color-data", options.depth_step.color_data_weight);
  app.add_option("--depth-lambda-rgb", options.depth_step.lambda_r);
  app.add_option("--color-smoothness", options.color_step.smoothness);
  app.add_option("--color-lambda-d", options.color_step.lambda_d);
  app.add_option("--color-depth-data", options.color_step.depth_data_weight);
  app.add_option("--rgbd-smoothness", options.rgbd_step.smoothness);
  app.add_option("--depth-depth-data", options.depth_step.depth_data_weight);
  bool depth_median = false, color_median = false;
  app.add_flag("--depth-median", depth_median);
  app.add_flag("--color-median", color_median);
  app.add_option("--color-color-data", options.color_step.color_data_weight);
  app.add_option("--color-bias", options.color_step.foreground_bias);
  app.add_option("--ring-radius", options.ring_radius_cells);
  app.add_option("--roi-margin", options.roi_margin_cells, "step-3 ROI margin, cells (0 = whole image)");
  app.add_option("--roi-fraction", options.roi_margin_fraction, "step-3 ROI margin, fraction of the box");
  app.add_option("--ring-threshold", options.ring_depth_threshold_m);
  app.add_option("--background-uniform", options.background_uniform);
  app.add_option("--sigma-scale", options.sigma_scale);
  app.add_option("--reference-spacing", options.reference_spacing_m,
                 "scale_to_data: reference ray spacing, m");
  app.add_flag("!--no-scale", options.scale_to_data, "no scaling of the metric lengths to the data");
  app.add_option("--grow-jump-cells", options.whole_object.jump_cells,
                 "whole-object growth: depth continuity, cells");
  app.add_option("--grow-crease-deg", options.whole_object.max_crease_deg,
                 "whole-object growth: largest crease, degrees");
  app.add_option("--grow-max", options.whole_object.max_growth,
                 "whole-object growth: at most this times the cut");
  app.add_flag("!--no-grow", options.grow_whole_object, "no whole-object growth");
  app.add_option("--coarse-max-cells", options.coarse_max_cells,
                 "coarse to fine above this many cells (0 = always full resolution)");
  app.add_option("--crevice-flank-deg", options.whole_object.crevice_flank_deg,
                 "touching neighbours: steepness of a crevice's flanks, degrees");
  app.add_option("--crevice-baseline", options.whole_object.crevice_baseline_cells,
                 "touching neighbours: the flanks' rise is measured over this many cells");
  app.add_option("--neighbour-fraction", options.whole_object.neighbour_min_fraction,
                 "touching neighbours: smallest part dropped, times the stroked parts' cells");
  app.add_option("--support-tilt-deg", options.whole_object.support_max_tilt_deg,
                 "whole-object growth: largest tilt of a support cell's normal, degrees");
  app.add_flag("!--no-overhangs", options.whole_object.join_overhangs, "no joining of overhanging parts");
  app.add_flag("!--no-separate", options.whole_object.separate_touching,
               "no separation of touching neighbours");
  app.add_flag("!--no-join-steps", options.whole_object.join_steps,
               "no joining of parts across a depth step");
  app.add_flag("!--no-rests-on", options.whole_object.join_rests_on,
               "no joining of parts the object rests on");
  app.add_option("--support-distance", options.whole_object.support_distance_m,
                 "whole-object growth: a cell this close to a support plane is support, metres");
  app.add_option("--join-crease-deg", options.whole_object.join_max_crease_deg,
                 "parts across a depth step: largest angle between neighbouring normals, degrees");
  app.add_option("--rests-on-max", options.whole_object.rests_on_max_growth,
                 "parts the object rests on: at most this many times its cells");
  app.add_option("--strip-max-cells", options.whole_object.strip_max_cells,
                 "the cuts drop strips of at most this many rows they follow along the scene (0 = keeps)");
  bool eight = false;
  std::string dump_dir;
  app.add_option("--dump", dump_dir,
                 "write overlays (step 1 + inferred background, final, grabCut) here (random scenes: of the "
                 "three worst seeds)");
  app.add_flag("--eight", eight);
  bool compare_window = false;
  app.add_flag(
      "--compare-window", compare_window,
      "compare the windowed two-step cut (window_margin_cells) with the whole-scan cut on the scenes "
      "(and the random seeds when given) instead of the tables");
  app.add_option("--window-margin", options.window_margin_cells,
                 "the cuts' window margin, cells (0 = whole scan)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (!dump_dir.empty()) std::filesystem::create_directories(dump_dir);
  options.depth_step.lambda_g = options.depth_step.lambda_b = options.depth_step.lambda_r;
  options.depth_step.median_sigma = options.depth_step.median_sigma || depth_median;
  options.color_step.median_sigma = options.color_step.median_sigma || color_median;
  options.eight_connected = eight;
  options.Check();
  if (compare_window) {
    try {
      WindowComparison set;
      std::vector<std::string> paths;
      for (const auto& entry : std::filesystem::directory_iterator(scenes_dir))
        if (entry.path().extension() == ".json") paths.push_back(entry.path().string());
      std::sort(paths.begin(), paths.end());
      for (const std::string& path : paths) {
        const Scan scan = SynthesizeScan(LoadScene(path));
        const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
        for (int seed = 1; seed <= seeds; ++seed) {
          const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, static_cast<uint64_t>(seed) * 7919 + 1);
          set.Add(fmt::format("{}/{}", std::filesystem::path(path).stem().string(), seed), scan, strokes,
                  options);
        }
      }
      fmt::print(
          "{}", set.Report(fmt::format("evaluation set ({} scenes x {} stroke seeds)", paths.size(), seeds)));
      if (!random_seeds.empty()) {
        WindowComparison random;
        for (uint64_t seed : test_scenes::ParseSeedRange(random_seeds)) {
          const RandomCase random_case = MakeRandomCase(seed, scene_options);
          if (random_case.strokes.empty()) continue;  // no room for strokes (as the random evaluation)
          random.Add(fmt::format("seed {}", seed), random_case.scan, random_case.strokes, options);
        }
        fmt::print("{}", random.Report(fmt::format("random scenes {}", random_seeds)));
      }
      return 0;
    } catch (const std::exception& error) {
      fmt::print(stderr, "segment_eval: {}\n", error.what());
      return 2;
    }
  }
  if (!random_seeds.empty()) {
    try {
      const std::vector<uint64_t> seeds = test_scenes::ParseSeedRange(random_seeds);
      scene_options.Check();
      return RunRandom(seeds, scene_options, options, grabcut_iterations, dump_dir, markdown_path);
    } catch (const std::exception& error) {
      fmt::print(stderr, "segment_eval: {}\n", error.what());
      return 2;
    }
  }

  std::vector<std::string> scene_paths;
  for (const auto& entry : std::filesystem::directory_iterator(scenes_dir)) {
    if (entry.path().extension() == ".json") scene_paths.push_back(entry.path().string());
  }
  std::sort(scene_paths.begin(), scene_paths.end());
  std::vector<AppearanceModel> models;
  if (model == "both" || model == "histogram") models.push_back(AppearanceModel::kHistogram);
  if (model == "both" || model == "gmm") models.push_back(AppearanceModel::kGmm);

  test_scenes::EvalReport report;
  auto emit = [&](const std::string& text) { report.Emit(text); };
  const std::vector<std::string> order = {"two-step", "step-1", "depth", "color", "rgbd", "grabcut"};
  for (AppearanceModel m : models) {
    options.model = m;
    std::map<std::string, std::vector<MaskScores>> all;
    std::map<std::string, double> seconds;
    emit(fmt::format("\n### Appearance model: {} ({} scenes x {} stroke seeds)\n\n", ToString(m),
                     scene_paths.size(), seeds));
    emit("| scene | cells | object | " + fmt::format("{}", fmt::join(order, " | ")) + " |\n");
    std::string separator = "|---|---|---|";
    for (size_t k = 0; k < order.size(); ++k) separator += "---|";
    emit(separator + "\n");
    for (const std::string& path : scene_paths) {
      const SceneDescription scene = LoadScene(path);
      const Scan scan = SynthesizeScan(scene);
      const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
      std::map<std::string, std::vector<double>> iou;
      for (int seed = 1; seed <= seeds; ++seed) {
        const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, static_cast<uint64_t>(seed) * 7919 + 1);
        if (!dump_dir.empty()) {
          const std::string stem = std::filesystem::path(path).stem().string();
          const cv::Mat both = Panel(scan, truth, strokes, options, 5);
          WriteImage(dump_dir + "/" + stem + (seed == 1 ? "" : "_seed" + std::to_string(seed)) + ".png",
                     both);
        }
        for (const MethodScores& s :
             EvaluateMethods(scan, truth, strokes, options, m == models.front() ? grabcut_iterations : 0)) {
          all[s.method].push_back(s.scores);
          iou[s.method].push_back(s.scores.iou);
          seconds[s.method] += s.seconds;
        }
      }
      std::string row = fmt::format("| {} | {} | {} |", std::filesystem::path(path).stem().string(),
                                    scan.CountValid(), cv::countNonZero(truth));
      for (const std::string& name : order) {
        if (iou[name].empty()) {
          row += " – |";
          continue;
        }
        double mean = 0;
        for (double v : iou[name]) mean += v;
        row += fmt::format(" {:.3f} |", mean / iou[name].size());
      }
      emit(row + "\n");
    }
    emit(
        "\n| method | mean IoU | mean precision | mean recall | min precision | runs | total s |\n"
        "|---|---|---|---|---|---|---|\n");
    for (const std::string& name : order) {
      const auto& v = all[name];
      if (v.empty()) continue;
      double iou = 0, precision = 0, recall = 0, min_precision = 1;
      for (const MaskScores& s : v) {
        iou += s.iou;
        precision += s.precision;
        recall += s.recall;
        min_precision = std::min(min_precision, s.precision);
      }
      emit(fmt::format("| {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {:.2f} |\n", name, iou / v.size(),
                       precision / v.size(), recall / v.size(), min_precision, v.size(), seconds[name]));
    }
  }
  report.Write(markdown_path);
  return 0;
}
