// Speed of the two-step segmentation on a 1000 x 1000 scan (the electric box in grass of data/segment_eval,
// scanned at 1000 x 1000), of a refinement after one extra stroke, and of OpenCV grabCut on the same image
// and strokes in the same run.
//
//   ninja -C build/segment segment_bench && build/segment/bench/segment_bench
#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_eval.h"

namespace lidarshop {
namespace {

struct Fixture {
  Scan scan;
  cv::Mat truth, strokes, extra;
};

const Fixture& GetFixture() {
  static const Fixture fixture = [] {
    Fixture f;
    SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/segment_eval/electric_box_grass.json");
    scene.scanner.columns = 1000;
    scene.scanner.rows = 1000;
    f.scan = SynthesizeScan(scene);
    f.truth = (f.scan.label == 1) & (f.scan.valid != 0);
    EvalStrokeOptions stroke_options;
    stroke_options.stroke_length_cells = 40;
    stroke_options.stroke_width_cells = 3;
    f.strokes = MakeEvalStrokes(f.truth, f.scan.valid, 1, stroke_options);
    // The extra stroke: a 40-cell object stroke through the largest part of the object the first cut missed
    // (where a user would add one), or, when nothing was missed, a background stroke below the object.
    f.extra = cv::Mat(f.scan.rows, f.scan.cols, CV_8U, cv::Scalar(kStrokeNone));
    const cv::Mat first = SegmentObject(f.scan, f.strokes).mask;
    cv::Mat missed = f.truth & ~first, labels, stats, centroids;
    cv::erode(missed, missed, cv::Mat());
    const int count = cv::connectedComponentsWithStats(missed, labels, stats, centroids, 4);
    int best = 0;
    for (int k = 1; k < count; ++k) {
      if (best == 0 || stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = k;
    }
    if (best > 0) {
      const cv::Point c(static_cast<int>(centroids.at<double>(best, 0)),
                        static_cast<int>(centroids.at<double>(best, 1)));
      cv::Mat line(f.scan.rows, f.scan.cols, CV_8U, cv::Scalar(0));
      cv::line(line, c - cv::Point(20, 0), c + cv::Point(20, 0), cv::Scalar(255), 3);
      f.extra.setTo(kStrokeObject, line & (labels == best));
    } else {
      const cv::Rect box = cv::boundingRect(f.truth);
      const int row = std::min(f.scan.rows - 1, box.y + box.height + 8);
      cv::line(f.extra, cv::Point(box.x + box.width / 2 - 20, row),
               cv::Point(box.x + box.width / 2 + 20, row), cv::Scalar(kStrokeBackground), 3);
    }
    return f;
  }();
  return fixture;
}

void Segment(benchmark::State& state, SegmentMethod method, AppearanceModel model, int roi_margin_cells = -1,
             double roi_margin_fraction = -1, int coarse_max_cells = -1) {
  const Fixture& f = GetFixture();
  SegmentOptions options;
  options.method = method;
  options.model = model;
  if (roi_margin_cells >= 0) options.roi_margin_cells = roi_margin_cells;
  if (roi_margin_fraction >= 0) options.roi_margin_fraction = roi_margin_fraction;
  if (coarse_max_cells >= 0) options.coarse_max_cells = coarse_max_cells;
  SegmentResult result;
  for (auto _ : state) {
    SegmentSession session(f.scan, options);
    result = session.Run(f.strokes);
    benchmark::DoNotOptimize(result.mask.data);
  }
  const MaskScores scores = ScoreMask(result.mask, f.truth, f.scan.valid);
  state.counters["IoU"] = scores.iou;
  state.counters["maxflow_s"] = result.timings.maxflow_s;
  state.counters["graph_s"] = result.timings.graph_s;
  state.counters["models_s"] = result.timings.models_s;
  state.counters["features_s"] = result.timings.features_s;
  state.counters["cells"] = static_cast<double>(f.scan.CountValid());
  state.counters["last_graph_nodes"] = static_cast<double>(result.graph_nodes);
  state.counters["coarse_factor"] = result.coarse_factor;
}

void BM_TwoStepGmm(benchmark::State& state) {
  Segment(state, SegmentMethod::kTwoStep, AppearanceModel::kGmm);
}
// Step 3 on the whole image (roi_margin_cells = 0), the behaviour before the region of interest.
void BM_TwoStepGmmWholeImage(benchmark::State& state) {
  Segment(state, SegmentMethod::kTwoStep, AppearanceModel::kGmm, 0);
}
// Step 3's ROI margin as a fraction of the step-1 box, in percent (the margin is at least 50 cells).
void BM_TwoStepGmmRoiFraction(benchmark::State& state) {
  Segment(state, SegmentMethod::kTwoStep, AppearanceModel::kGmm, 50, state.range(0) / 100.0);
}
// Coarse to fine (SegmentOptions::coarse_max_cells) on the level of every f-th ray, f = the argument: the
// 1000 x 1000 scan is at the default's limit, so it is cut at full resolution unless asked.
void BM_TwoStepGmmCoarseToFine(benchmark::State& state) {
  const int factor = static_cast<int>(state.range(0));
  Segment(state, SegmentMethod::kTwoStep, AppearanceModel::kGmm, -1, -1, 1000000 / (factor * factor));
}
void BM_TwoStepHistogram(benchmark::State& state) {
  Segment(state, SegmentMethod::kTwoStep, AppearanceModel::kHistogram);
}
void BM_OneCutDepthHistogram(benchmark::State& state) {
  Segment(state, SegmentMethod::kDepth, AppearanceModel::kHistogram);
}

// Refinement after one extra stroke: the session has run (untimed); the timed part is Refine(). IoU before
// the stroke is BM_TwoStepGmm's.
void Refine(benchmark::State& state, bool relearn) {
  const Fixture& f = GetFixture();
  SegmentOptions options;
  options.refine_relearn_models = relearn;
  SegmentResult result;
  for (auto _ : state) {
    state.PauseTiming();
    SegmentSession session(f.scan, options);
    session.Run(f.strokes);
    state.ResumeTiming();
    result = session.Refine(f.extra);
    benchmark::DoNotOptimize(result.mask.data);
  }
  state.counters["IoU"] = ScoreMask(result.mask, f.truth, f.scan.valid).iou;
  state.counters["stroke_cells"] = cv::countNonZero(f.extra);
}

void BM_RefineOneStroke(benchmark::State& state) { Refine(state, true); }
void BM_RefineOneStrokeHardOnly(benchmark::State& state) { Refine(state, false); }

// The same refinement done the slow way: a full two-step Run with the extra stroke added (for the ratio).
void BM_RerunWithExtraStroke(benchmark::State& state) {
  const Fixture& f = GetFixture();
  cv::Mat strokes = f.strokes.clone();
  strokes.setTo(kStrokeBackground, f.extra == kStrokeBackground);
  strokes.setTo(kStrokeObject, f.extra == kStrokeObject);
  SegmentResult result;
  for (auto _ : state) {
    SegmentSession session(f.scan, SegmentOptions());
    result = session.Run(strokes);
    benchmark::DoNotOptimize(result.mask.data);
  }
  state.counters["IoU"] = ScoreMask(result.mask, f.truth, f.scan.valid).iou;
}

void BM_OpenCvGrabCut(benchmark::State& state) {
  const Fixture& f = GetFixture();
  cv::Mat mask;
  for (auto _ : state) {
    mask = GrabCutFromStrokes(f.scan, f.strokes, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(mask.data);
  }
  state.counters["IoU"] = ScoreMask(mask, f.truth, f.scan.valid).iou;
}

BENCHMARK(BM_TwoStepGmm)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_TwoStepGmmWholeImage)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_TwoStepGmmRoiFraction)->Arg(10)->Arg(25)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_TwoStepGmmCoarseToFine)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_TwoStepHistogram)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_OneCutDepthHistogram)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_RefineOneStroke)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_RefineOneStrokeHardOnly)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_RerunWithExtraStroke)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_OpenCvGrabCut)->Arg(1)->Arg(5)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
