// Wall time of `lidarshop sweep`'s default grid (x −10..10 m, y 0..20 m every 0.25 m, yaws every 15°:
// 157,464 poses) with the sedan model over the built-in parking lot (data/scenes/parking_lot.json, its
// 960 x 560 scan), the full grid against the coarse-to-fine search (verify/sweep.h), one run each:
//  * BM_Sweep/0 — SweepSearch::kFull: every grid pose verified;
//  * BM_Sweep/1 — SweepSearch::kCoarseToFine (the default): bounds, then only the poses that can pass.
// Counters: poses verified, confidence bounds computed, detections, and (coarse-to-fine, when the full grid
// ran first in the same process) `same_detections` = 1 when both gave identical detections (poses and
// values) and refined poses. Refinement is on, as in the command.
//
//   cmake --build build/release --target sweep_bench && build/release/bench/sweep_bench
//   build/release/bench/sweep_bench --benchmark_filter='BM_Sweep/1'   # coarse-to-fine only
#include <optional>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {
namespace {

struct Setup {
  VerifierModel model;
  std::vector<PreparedScan> scans;
};

const Setup& TheSetup() {
  static const Setup setup = [] {
    Setup s;
    const SceneDescription scene =
        LoadScene(std::string(LIDARSHOP_SOURCE_DIR) + "/data/scenes/parking_lot.json");
    s.scans.push_back(PrepareScan(SyntheticScanner(scene).Acquire(scene.scanner)));
    CarMeshOptions car;
    car.style = ParseCarStyle("sedan", "bench");
    s.model = PrepareModel(MakeCarMesh(car));
    return s;
  }();
  return setup;
}

// The command's default grid (lidarshop sweep without range or yaw flags).
SweepOptions DefaultCommandGrid(SweepSearch search) {
  SweepOptions options;
  options.yaws_deg.clear();
  for (int yaw = 0; yaw < 360; yaw += 15) options.yaws_deg.push_back(yaw);
  options.search = search;
  return options;
}

bool SameDetections(const SweepResult& a, const SweepResult& b) {
  if (a.detections.size() != b.detections.size() || a.refined.size() != b.refined.size()) return false;
  for (size_t k = 0; k < a.detections.size(); ++k) {
    const Detection& p = a.detections[k];
    const Detection& q = b.detections[k];
    if (p.x_m != q.x_m || p.y_m != q.y_m || p.yaw_deg != q.yaw_deg || p.consistency != q.consistency ||
        p.confidence != q.confidence || p.comparable_pairs != q.comparable_pairs) {
      return false;
    }
  }
  for (size_t k = 0; k < a.refined.size(); ++k) {
    if (a.refined[k].x_m != b.refined[k].x_m || a.refined[k].y_m != b.refined[k].y_m ||
        a.refined[k].yaw_deg != b.refined[k].yaw_deg) {
      return false;
    }
  }
  return true;
}

std::optional<SweepResult> full_result;

void BM_Sweep(benchmark::State& state) {
  const Setup& setup = TheSetup();
  const SweepSearch search = state.range(0) == 0 ? SweepSearch::kFull : SweepSearch::kCoarseToFine;
  const SweepOptions options = DefaultCommandGrid(search);
  SweepResult result;
  for (auto _ : state) {
    result = Sweep(setup.model, setup.scans, options, VerifyOptions());
    benchmark::DoNotOptimize(result.detections.data());
  }
  state.counters["grid_poses"] = static_cast<double>(result.poses.size());
  state.counters["verified_poses"] = static_cast<double>(result.evaluated_poses);
  state.counters["bounds"] = static_cast<double>(result.bound_evaluations);
  state.counters["refine_poses"] = static_cast<double>(result.refine_evaluations);
  state.counters["detections"] = static_cast<double>(result.detections.size());
  std::string text;
  for (const Detection& d : result.detections) {
    text += fmt::format(" ({:.3f}, {:.3f}, {:.2f}°: {:.4f} / {:.4f})", d.x_m, d.y_m, d.yaw_deg, d.consistency,
                        d.confidence);
  }
  if (search == SweepSearch::kFull) {
    full_result = result;
  } else if (full_result) {
    state.counters["same_detections"] = SameDetections(result, *full_result) ? 1 : 0;
  }
  state.SetLabel(fmt::format("{}:{}", search == SweepSearch::kFull ? "full" : "coarse-to-fine", text));
}
// Process CPU time (all threads): the machine is shared, and on two free cores the wall time is about half.
BENCHMARK(BM_Sweep)->Arg(0)->Arg(1)->Iterations(1)->UseRealTime()->MeasureProcessCPUTime()->Unit(
    benchmark::kSecond);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
