// Poisson solvers side by side in one run: our MGPCG, CHOLMOD and Eigen's SimplicialLDLT on the same Laplace
// fills of 100k and 1M unknowns; and seamless cloning against OpenCV's cv::seamlessClone on f16 + canyon,
// with the target enlarged (same hole) to see which time follows the image and which the hole.
//
//   ninja -C build/poisson poisson_bench && build/poisson/bench/poisson_bench
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "lidarshop/poisson/operators.h"
#include "lidarshop/poisson/poisson.h"

namespace lidarshop {
namespace {

struct FillProblem {
  cv::Mat image;  // CV_32F, one channel
  cv::Mat mask;   // a disc of about `unknowns` pixels with a margin of 32 pixels
};

const FillProblem& Problem(int unknowns) {
  static std::map<int, FillProblem> cache;
  auto it = cache.find(unknowns);
  if (it != cache.end()) return it->second;
  const int radius = static_cast<int>(std::lround(std::sqrt(unknowns / M_PI)));
  const int side = 2 * radius + 64;
  FillProblem problem;
  problem.image.create(side, side, CV_32F);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> noise(-10.0f, 10.0f);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      problem.image.at<float>(y, x) =
          128.0f + 60.0f * std::sin(0.01f * x) * std::cos(0.013f * y) + noise(rng);
    }
  }
  problem.mask = cv::Mat::zeros(side, side, CV_8U);
  cv::circle(problem.mask, cv::Point(side / 2, side / 2), radius, 255, cv::FILLED);
  return cache.emplace(unknowns, std::move(problem)).first->second;
}

PoissonOptions OptionsFor(int solver) {
  PoissonOptions options;
  options.solver = (solver == 0 || solver == 3) ? PoissonSolverKind::kMultigrid : PoissonSolverKind::kDirect;
  if (solver == 3) options.smoothing_sweeps = 1;  // ablation: one sweep before and after
  options.direct_backend = solver == 2 ? PoissonDirectBackend::kEigenLdlt : PoissonDirectBackend::kCholmod;
  options.tolerance = 1e-6;
  return options;
}

// Prepare (factor / build hierarchy) + solve one channel: the cost of one fill on a new mask.
void BM_LaplaceFill(benchmark::State& state, int solver) {
  const FillProblem& problem = Problem(static_cast<int>(state.range(0)));
  PoissonResult result;
  double prepare = 0.0;
  for (auto _ : state) {
    const PoissonSystem system = PreparePoisson(problem.mask, OptionsFor(solver));
    result = FillLaplace(system, problem.image);
    prepare = system.PrepareSeconds();
  }
  state.counters["unknowns"] = cv::countNonZero(problem.mask);
  state.counters["iterations"] = result.iterations;
  state.counters["rel_residual"] = result.relative_residual;
  state.counters["prepare_s"] = prepare;
  state.counters["solve_s"] = result.seconds;
}

// Solve only, on a prepared system: the cost of each further right-hand side / channel on the same mask.
void BM_LaplaceSolveOnly(benchmark::State& state, int solver) {
  const FillProblem& problem = Problem(static_cast<int>(state.range(0)));
  const PoissonSystem system = PreparePoisson(problem.mask, OptionsFor(solver));
  PoissonResult result;
  for (auto _ : state) result = FillLaplace(system, problem.image);
  state.counters["unknowns"] = system.NumUnknowns();
  state.counters["iterations"] = result.iterations;
  state.counters["rel_residual"] = result.relative_residual;
}

struct CloneProblem {
  cv::Mat source_bgr, mask, target_bgr;  // OpenCV's BGR order for seamlessClone; ours is order-agnostic
  cv::Point offset{110, 130};            // target position of source pixel (0, 0)
  cv::Point center;                      // the same placement in seamlessClone's convention
};

const CloneProblem& Clone(int scale) {
  static std::map<int, CloneProblem> cache;
  auto it = cache.find(scale);
  if (it != cache.end()) return it->second;
  const std::string folder = LIDARSHOP_SHARED_DATA_DIR "/images/f16/";
  CloneProblem problem;
  problem.source_bgr = cv::imread(folder + "f16.png", cv::IMREAD_COLOR);
  problem.mask = cv::imread(folder + "f16_mask.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat canyon = cv::imread(folder + "canyon.png", cv::IMREAD_COLOR);
  if (problem.source_bgr.empty() || problem.mask.empty() || canyon.empty()) {
    throw std::runtime_error("f16 data not found in " + folder);
  }
  cv::threshold(problem.mask, problem.mask, 127, 255, cv::THRESH_BINARY);
  // OpenCV clears the mask's outer 1-pixel frame; do the same so both clone the same region.
  problem.mask.row(0).setTo(0);
  problem.mask.row(problem.mask.rows - 1).setTo(0);
  problem.mask.col(0).setTo(0);
  problem.mask.col(problem.mask.cols - 1).setTo(0);
  cv::resize(canyon, problem.target_bgr, cv::Size(), scale, scale, cv::INTER_LINEAR);
  const cv::Rect box = cv::boundingRect(problem.mask);
  problem.center =
      cv::Point(problem.offset.x + box.x + box.width / 2, problem.offset.y + box.y + box.height / 2);
  return cache.emplace(scale, std::move(problem)).first->second;
}

void BM_CloneOurs(benchmark::State& state) {
  const CloneProblem& problem = Clone(static_cast<int>(state.range(0)));
  PoissonResult result;
  for (auto _ : state) {
    result = SeamlessClone(problem.source_bgr, problem.mask, problem.target_bgr, problem.offset);
  }
  state.counters["unknowns"] = cv::countNonZero(problem.mask);
  state.counters["target_px"] = problem.target_bgr.total();
  state.counters["rel_residual"] = result.relative_residual;
  // PSNR (8-bit) of our clone against OpenCV's inside the cloned region.
  cv::Mat ours, theirs;
  result.image.convertTo(ours, CV_8UC3);  // saturating round, as OpenCV's output
  cv::seamlessClone(problem.source_bgr, problem.target_bgr, problem.mask, problem.center, theirs,
                    cv::NORMAL_CLONE);
  const cv::Mat region = CloneMaskInTarget(problem.mask, problem.target_bgr.size(), problem.offset);
  cv::Mat diff;
  cv::absdiff(ours, theirs, diff);
  diff.convertTo(diff, CV_64FC3);
  diff = diff.mul(diff);
  const cv::Scalar sum = cv::sum(diff.setTo(0.0, region == 0));
  const double mse = (sum[0] + sum[1] + sum[2]) / (3.0 * cv::countNonZero(region));
  state.counters["psnr_vs_opencv_db"] = mse > 0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 999.0;
}

void BM_CloneOpenCV(benchmark::State& state) {
  const CloneProblem& problem = Clone(static_cast<int>(state.range(0)));
  cv::Mat blend;
  for (auto _ : state) {
    cv::seamlessClone(problem.source_bgr, problem.target_bgr, problem.mask, problem.center, blend,
                      cv::NORMAL_CLONE);
  }
  state.counters["target_px"] = problem.target_bgr.total();
}

void Register() {
  for (int unknowns : {100000, 1000000}) {
    const bool big = unknowns >= 1000000;
    benchmark::RegisterBenchmark("LaplaceFill/multigrid", BM_LaplaceFill, 0)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->MinTime(big ? 2.0 : 0.5);
    benchmark::RegisterBenchmark("LaplaceFill/cholmod", BM_LaplaceFill, 1)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->Iterations(big ? 2 : 5);
    benchmark::RegisterBenchmark("LaplaceFill/eigen_simplicial_ldlt", BM_LaplaceFill, 2)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->Iterations(1);
    benchmark::RegisterBenchmark("LaplaceSolveOnly/multigrid", BM_LaplaceSolveOnly, 0)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->MinTime(big ? 2.0 : 0.5);
    benchmark::RegisterBenchmark("LaplaceSolveOnly/multigrid_1sweep", BM_LaplaceSolveOnly, 3)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->MinTime(big ? 2.0 : 0.5);
    benchmark::RegisterBenchmark("LaplaceSolveOnly/cholmod", BM_LaplaceSolveOnly, 1)
        ->Arg(unknowns)
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime()
        ->MinTime(big ? 2.0 : 0.5);
  }
  for (int scale : {1, 2, 4}) {
    benchmark::RegisterBenchmark("SeamlessClone/lidarshop", BM_CloneOurs)
        ->Arg(scale)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("SeamlessClone/opencv", BM_CloneOpenCV)
        ->Arg(scale)
        ->Unit(benchmark::kMillisecond);
  }
}

// --pictures=DIR writes the evidence pictures (small PNGs) and prints their numbers; --gradients=DIR writes
// f16's forward gradients as EXR for `lidarshop poisson reconstruct`.
void WritePictures(const std::string& folder, const std::string& gradient_folder) {
  const CloneProblem& problem = Clone(1);
  const PoissonResult ours =
      SeamlessClone(problem.source_bgr, problem.mask, problem.target_bgr, problem.offset);
  cv::Mat ours8, theirs;
  ours.image.convertTo(ours8, CV_8UC3);
  cv::seamlessClone(problem.source_bgr, problem.target_bgr, problem.mask, problem.center, theirs,
                    cv::NORMAL_CLONE);
  cv::Mat naive = problem.target_bgr.clone();
  problem.source_bgr(cv::Rect(0, 0, problem.source_bgr.cols, problem.source_bgr.rows))
      .copyTo(naive(cv::Rect(problem.offset, problem.source_bgr.size())), problem.mask);
  if (!folder.empty()) {
    cv::imwrite(folder + "/f16_clone_canyon_opencv.png", theirs);
    cv::imwrite(folder + "/f16_paste_canyon_naive.png", naive);
  }
  std::printf(
      "clone f16 -> canyon: %s; PSNR vs OpenCV seamlessClone inside the region printed by the bench\n",
      ours.Summary().c_str());

  // Reconstruction of f16 from its own gradients inside the f16 mask, both solvers.
  cv::Mat f16;
  problem.source_bgr.convertTo(f16, CV_64FC3);
  const ImageGradient gradient = ForwardGradient(f16);
  for (int solver : {1, 0}) {
    PoissonOptions options = OptionsFor(solver);
    options.tolerance = 1e-10;
    const PoissonSystem system = PreparePoisson(problem.mask, options);
    const PoissonResult result = ReconstructFromGradients(system, f16, gradient.gx, gradient.gy);
    cv::Mat diff;
    cv::absdiff(result.image, f16, diff);
    double max_error = 0.0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max_error);
    std::printf(
        "reconstruct f16 from its own gradients (%d unknowns x 3): %s; max |error| %.3g grey levels\n",
        system.NumUnknowns(), result.Summary().c_str(), max_error);
  }
  // Laplace fill of the f16 mask region, for the picture.
  cv::Mat f16_float;
  problem.source_bgr.convertTo(f16_float, CV_32FC3);
  const PoissonResult fill = FillLaplace(PreparePoisson(problem.mask), f16_float);
  std::printf("Laplace fill of f16_mask on f16: %s\n", fill.Summary().c_str());
  if (!gradient_folder.empty()) {
    setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
    // The gradients are of the BGR image and cv::imwrite writes BGR, so the files
    // hold RGB as lidarshop expects.
    cv::Mat gx, gy;
    gradient.gx.convertTo(gx, CV_32FC3);
    gradient.gy.convertTo(gy, CV_32FC3);
    cv::imwrite(gradient_folder + "/f16_gx.exr", gx);
    cv::imwrite(gradient_folder + "/f16_gy.exr", gy);
  }
}

}  // namespace
}  // namespace lidarshop

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::string pictures, gradients;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--pictures=", 0) == 0) pictures = arg.substr(11);
    if (arg.rfind("--gradients=", 0) == 0) gradients = arg.substr(12);
  }
  if (!pictures.empty() || !gradients.empty()) {
    lidarshop::WritePictures(pictures, gradients);
    return 0;
  }
  lidarshop::Register();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
