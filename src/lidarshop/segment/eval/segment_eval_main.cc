// segment_eval: quality of the two-step segmentation against its baselines on the synthetic evaluation set.
//
//   segment_eval [--scenes DIR] [--seeds N] [--model histogram|gmm|both] [--markdown FILE]
//
// Every data/segment_eval/*.json scene is scanned with the synthetic scanner (scanner/scanner.h); the target
// object is label 1. For each stroke seed, one short stroke inside the eroded object and one in the
// background are drawn (MakeEvalStrokes) and every method runs on the same strokes. Prints per-scene IoU and
// the mean IoU, precision and recall of every method; with --markdown, writes the tables there too.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment_eval.h"

using namespace lidarshop;

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
  bool eight = false;
  std::string dump_dir;
  app.add_option("--dump", dump_dir, "write overlays (step 1 + inferred background, final, grabCut) here");
  app.add_flag("--eight", eight);
  CLI11_PARSE(app, argc, argv);
  if (!dump_dir.empty()) std::filesystem::create_directories(dump_dir);
  options.depth_step.lambda_g = options.depth_step.lambda_b = options.depth_step.lambda_r;
  options.depth_step.median_sigma = options.depth_step.median_sigma || depth_median;
  options.color_step.median_sigma = options.color_step.median_sigma || color_median;
  options.eight_connected = eight;
  options.Check();

  std::vector<std::string> scene_paths;
  for (const auto& entry : std::filesystem::directory_iterator(scenes_dir)) {
    if (entry.path().extension() == ".json") scene_paths.push_back(entry.path().string());
  }
  std::sort(scene_paths.begin(), scene_paths.end());
  std::vector<AppearanceModel> models;
  if (model == "both" || model == "histogram") models.push_back(AppearanceModel::kHistogram);
  if (model == "both" || model == "gmm") models.push_back(AppearanceModel::kGmm);

  std::string report;
  auto emit = [&](const std::string& text) {
    fmt::print("{}", text);
    report += text;
  };
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
          SegmentOptions o = options;
          o.method = SegmentMethod::kTwoStep;
          const SegmentResult r = SegmentObject(scan, strokes, o);
          cv::Mat step1 = SegmentOverlay(scan, r.step1_mask, strokes);
          step1.setTo(cv::Scalar(255, 0, 255), r.inferred_background);
          cv::Mat row1, row2;
          cv::hconcat(step1, SegmentOverlay(scan, r.mask, strokes), row1);
          cv::hconcat(SegmentOverlay(scan, truth, strokes),
                      SegmentOverlay(scan, GrabCutFromStrokes(scan, strokes), strokes), row2);
          // Third row: the two-step errors, missed object cells red and extra cells blue, enlarged 2x.
          cv::Mat errors(scan.rows, scan.cols, CV_8UC3, cv::Scalar(60, 60, 60));
          errors.setTo(cv::Scalar(200, 200, 200), truth & r.mask);
          errors.setTo(cv::Scalar(255, 0, 0), truth & ~r.mask);
          errors.setTo(cv::Scalar(0, 80, 255), r.mask & ~truth & (scan.valid != 0));
          cv::Mat row3;
          cv::resize(errors, row3, row1.size(), 0, 0, cv::INTER_NEAREST);
          cv::Mat both;
          cv::vconcat(std::vector<cv::Mat>{row1, row2, row3}, both);
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
  if (!markdown_path.empty()) {
    std::ofstream out(markdown_path);
    out << report;
  }
  return 0;
}
