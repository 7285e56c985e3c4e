// Hole filling in scans, every method on the same hole in one run: a van removed from a 1000 x 1000 scan of
// data/fill_eval/facade_car.json (about 100,000 hole cells) and a disc of 100,000 cells in the same scan.
// Counters: hole cells, patches, candidates evaluated per patch and the patch fill's microseconds per patch
// (patch methods), the seconds of each step, and result_hash, a fingerprint of the filled scan.
//
//   ninja -C build/release fill_bench && build/release/bench/fill_bench --benchmark_min_time=1
#include <cmath>
#include <map>

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/fill/fill.h"
#include "lidarshop/scanner/scanner.h"

namespace lidarshop {
namespace {

struct Problem {
  Scan scan;
  cv::Mat hole;
};

// kind 0: the van's cells grown by 2; kind 1: a disc of 100,000 cells centred on the van.
const Problem& GetProblem(int kind) {
  static std::map<int, Problem> cache;
  if (auto it = cache.find(kind); it != cache.end()) return it->second;
  static const Scan scan = [] {
    SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/fill_eval/facade_car.json");
    scene.scanner.columns = 1000;
    scene.scanner.rows = 1000;
    return SynthesizeScan(scene);
  }();
  Problem problem{scan, {}};
  const cv::Mat van = (scan.label == 1) & (scan.valid != 0);
  if (kind == 0) {
    problem.hole = GrowHole(van, 2);
  } else {
    const cv::Moments m = cv::moments(van, true);
    problem.hole = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    const int radius = static_cast<int>(std::lround(std::sqrt(100000.0 / M_PI)));
    cv::circle(problem.hole, cv::Point(static_cast<int>(m.m10 / m.m00), static_cast<int>(m.m01 / m.m00)),
               radius, 255, cv::FILLED);
  }
  return cache.emplace(kind, std::move(problem)).first->second;
}

void BM_FillScan(benchmark::State& state, FillMethod method, bool acceptance, bool offsets = false,
                 InpaintSearchKind search = FillOptions().inpaint.search) {
  const Problem& problem = GetProblem(static_cast<int>(state.range(0)));
  FillOptions options;
  options.method = method;
  options.inpaint.acceptance.enabled = acceptance;
  options.offset_completion = offsets;
  options.inpaint.search = search;
  FillResult result;
  for (auto _ : state) {
    result = FillScan(problem.scan, problem.hole, options);
    benchmark::DoNotOptimize(result.scan.range.data);
  }
  {
    // A fingerprint of the filled scan (FNV-1a of its range, colour and intensity bytes, mod 99991): equal
    // between two builds when a speed-up left every fill unchanged.
    uint64_t h = 1469598103934665603ull;
    for (const cv::Mat& m : {result.scan.range, result.scan.color, result.scan.intensity}) {
      if (m.empty()) continue;
      cv::Mat c = m.clone();
      const uint8_t* b = c.ptr<uint8_t>();
      for (size_t i = 0; i < c.total() * c.elemSize(); ++i) h = (h ^ b[i]) * 1099511628211ull;
    }
    state.counters["result_hash"] = static_cast<double>(h % 99991);
  }
  state.counters["hole_cells"] = static_cast<double>(result.hole_cells);
  state.counters["patches"] = result.patches;
  if (result.patches > 0) {
    state.counters["candidates_per_patch"] =
        static_cast<double>(result.candidates_evaluated) / static_cast<double>(result.patches);
    // All of the patch fill (canvas, priorities, search, copies) per patch; the patch difference alone is
    // timed per candidate in inpaint_bench.
    state.counters["inpaint_us_per_patch"] = 1e6 * result.timings.inpaint_s / result.patches;
  }
  state.counters["inpaint_s"] = result.timings.inpaint_s;
  state.counters["lattice_s"] = result.timings.lattice_s;
  state.counters["lattice_cells"] = static_cast<double>(result.lattice_cells);
  state.counters["poisson_s"] = result.timings.poisson_s;
  state.counters["planes_s"] = result.timings.planes_s;
  state.counters["plane_cells"] = static_cast<double>(result.plane_cells);
  if (offsets) state.counters["offset_cells"] = static_cast<double>(result.offset_cells);
  state.counters["total_s"] = result.timings.total_s;
}

// The default (acceptance tests on), the same without them, and the baselines.
BENCHMARK_CAPTURE(BM_FillScan, gradient, FillMethod::kGradient, true)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// Opt-in: shifted copies at the dominant patch offsets first (inpaint/offset_completion.h).
BENCHMARK_CAPTURE(BM_FillScan, gradient_offsets, FillMethod::kGradient, true, true)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The exact search (two-step: the local window bounds the scan-wide search).
BENCHMARK_CAPTURE(BM_FillScan, gradient_exhaustive, FillMethod::kGradient, true, false,
                  InpaintSearchKind::kExhaustive)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FillScan, gradient_plain, FillMethod::kGradient, false)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FillScan, laplace, FillMethod::kLaplace, false)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FillScan, depth_patch, FillMethod::kDepthPatch, false)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FillScan, telea, FillMethod::kTelea, false)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
