// Poses per second of pose verification (consistency + confidence + trimmed ICP) for a 1000 x 1000 scan and a
// car-sized model of 221,184 triangles seen by about 12,000 rays, against a straightforward per-pose
// implementation (cast EVERY scan ray, rebuild the KD-tree per pose) in the same run:
//  * BM_VerifyPoses_Footprint/N — lidarshop's VerifyPoses on N threads (512 poses near the car);
//  * BM_VerifyPoses_Naive/2 — the straightforward implementation, one pose at a time (its ray cast uses both
//    threads, its KD-tree queries one);
//  * BM_VerifyPoses_NaiveParallel/2 — the same, two poses at a time (like-for-like with VerifyPoses);
//  * BM_Agreement — not timed: the two implementations give the same answers.
// Process CPU time per pose is reported too: its ratio is the speed-up of the method, independent of how
// either uses the threads.
//
//   ninja -C build/main verify_bench && build/main/bench/verify_bench
#include <cmath>
#include <numbers>
#include <random>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/pointset/kdtree.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/verify/verify.h"
#include "lidarshop/verify/verify_test_util.h"

namespace lidarshop {
namespace {

using verify_testing::LabeledMesh;
using verify_testing::MakeBox;

// The scanner module's sedan (4.6 x 1.8 x 1.45 m, length along y), subdivided to about 220,000 triangles.
TriangleMesh MakeCar() {
  CarMeshOptions options;
  options.subdivisions = 4;
  return MakeCarMesh(options);
}

// A rounded car-like body: a superellipsoid |x/a|^p + |y/b|^p + |z/c|^p = 1 (p = 4) of 4.5 x 1.8 x 1.5 m with
// `segments` x `segments` quads (2 segments² triangles), bottom at z = 0.
TriangleMesh MakeRoundedCar(int segments) {
  TriangleMesh mesh;
  const double a = 2.25, b = 0.9, c = 0.75, exponent = 2.0 / 4.0;
  auto signed_pow = [](double v, double e) { return std::copysign(std::pow(std::abs(v), e), v); };
  for (int i = 0; i <= segments; ++i) {
    const double v = -std::numbers::pi / 2 + std::numbers::pi * i / segments;
    for (int j = 0; j < segments; ++j) {
      const double u = 2 * std::numbers::pi * j / segments;
      mesh.vertices.emplace_back(
          static_cast<float>(a * signed_pow(std::cos(v), exponent) * signed_pow(std::cos(u), exponent)),
          static_cast<float>(b * signed_pow(std::cos(v), exponent) * signed_pow(std::sin(u), exponent)),
          static_cast<float>(c + c * signed_pow(std::sin(v), exponent)));
    }
  }
  for (int i = 0; i < segments; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int p0 = i * segments + j, p1 = i * segments + (j + 1) % segments;
      const int q0 = p0 + segments, q1 = p1 + segments;
      mesh.triangles.emplace_back(p0, p1, q1);
      mesh.triangles.emplace_back(p0, q1, q0);
    }
  }
  return mesh;
}

struct Fixture {
  TriangleMesh model_mesh = MakeCar();
  Eigen::Matrix4d world_from_car = PoseFromXyzYaw(0, 8.3, 0, 90);
  std::vector<PreparedScan> scans;
  VerifierModel model;
  std::vector<Eigen::Matrix4d> poses;  // hypotheses near the car (±0.5 m, ±20°)
  VerifyOptions options;

  Fixture() {
    // A 1000 x 1000 scan over 360° x 90° from 1.5 m height in a 60 x 60 m walled yard: every ray returns.
    std::vector<LabeledMesh> meshes = {
        {TransformMesh(model_mesh, world_from_car), 1},
        {MakeBox(Eigen::Vector3f(-30, -30, -0.2f), Eigen::Vector3f(30, 30, 0.0f)), 2},
        {MakeBox(Eigen::Vector3f(-30, 30, 0), Eigen::Vector3f(30, 30.5f, 20)), 3},
        {MakeBox(Eigen::Vector3f(-30, -30.5f, 0), Eigen::Vector3f(30, -30, 20)), 4},
        {MakeBox(Eigen::Vector3f(30, -30, 0), Eigen::Vector3f(30.5f, 30, 20)), 5},
        {MakeBox(Eigen::Vector3f(-30.5f, -30, 0), Eigen::Vector3f(-30, 30, 20)), 6},
    };
    scans.push_back(PrepareScan(verify_testing::SyntheticScan(meshes, PoseFromXyzYaw(0, 0, 1.5, 0), 1000,
                                                              1000, -180, 179.64, -60, 30)));
    model = PrepareModel(model_mesh);
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> offset(-0.5, 0.5), yaw(-20, 20);
    for (int p = 0; p < 512; ++p)
      poses.push_back(PoseFromXyzYaw(offset(random), 8.3 + offset(random), 0, 90 + yaw(random)));
  }
};

Fixture& GetFixture() {
  static Fixture fixture;
  return fixture;
}

// The straightforward implementation: per pose, move EVERY ray of the scan into the model frame and cast it,
// and build a KD-tree of the posed model points in the scanner frame to look up every scene point.
VerifyResult VerifyPoseNaive(const VerifierModel& model, const PreparedScan& prepared,
                             const Eigen::Matrix4d& world_from_model, const VerifyOptions& options) {
  VerifyResult result;
  const Scan& scan = prepared.scan;
  const Eigen::Matrix4d model_from_scanner = world_from_model.inverse() * prepared.world_from_scanner;
  const Eigen::Matrix4d scanner_from_model = model_from_scanner.inverse();
  const Eigen::Matrix3f linear = model_from_scanner.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f origin = model_from_scanner.topRightCorner<3, 1>().cast<float>();
  std::vector<Ray> rays;
  std::vector<float> ranges;
  std::vector<Eigen::Vector3f> scene_points;
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (scan.valid.at<uint8_t>(r, c) == 0) continue;
      const cv::Vec3f p = scan.point.at<cv::Vec3f>(r, c);
      const Eigen::Vector3f point(p[0], p[1], p[2]);
      const float range = scan.range.at<float>(r, c);
      Ray ray;
      ray.origin = origin;
      ray.direction = linear * (point / range);
      rays.push_back(ray);
      ranges.push_back(range);
      scene_points.push_back(point);
    }
  }
  std::vector<RayHit> hits(rays.size());
  model.scene_in_model.Cast(rays, hits);
  for (size_t k = 0; k < rays.size(); ++k) {
    if (!hits[k].hit()) continue;
    ++result.comparable_pairs;
    if (hits[k].t_hit + options.allowance_m - ranges[k] >= 0) ++result.consistent_pairs;
  }
  // Rebuilt per pose: the model points in the scanner frame.
  std::vector<Eigen::Vector3f> posed;
  for (const Eigen::Vector3f& p : model.points_in_model.points())
    posed.push_back(TransformPoint(scanner_from_model, p));
  const PointKdTree tree(std::move(posed));
  const float sigma = static_cast<float>(options.sigma_m);
  std::vector<float> sum(model.num_points(), 0.0f);
  std::vector<std::pair<uint32_t, float>> matches;
  for (const Eigen::Vector3f& point : scene_points) {
    tree.RadiusSearch(point, 3 * sigma, &matches);
    for (const auto& [i, distance_sq] : matches) sum[i] += std::exp(-distance_sq / (2 * sigma * sigma));
  }
  for (size_t i = 0; i < sum.size(); ++i) result.confidence += model.information[i] * std::min(1.0f, sum[i]);
  result.consistency =
      static_cast<double>(result.consistent_pairs) / std::max<int64_t>(1, result.comparable_pairs);
  return result;
}

void BM_VerifyPoses_Footprint(benchmark::State& state) {
  Fixture& fixture = GetFixture();
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  int64_t poses = 0, rays = 0, cells = 0;
  for (auto _ : state) {
    const std::vector<VerifyResult> results =
        VerifyPoses(fixture.model, fixture.scans, fixture.poses, fixture.options);
    for (const VerifyResult& result : results) {
      rays += result.per_scan[0].rays_cast;
      cells += result.per_scan[0].footprint_cells;
    }
    poses += static_cast<int64_t>(results.size());
    benchmark::DoNotOptimize(results.data());
  }
  state.SetItemsProcessed(poses);
  state.counters["rays_cast_per_pose"] = static_cast<double>(rays) / poses;
  state.counters["footprint_cells_per_pose"] = static_cast<double>(cells) / poses;
  state.counters["threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_VerifyPoses_Footprint)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->MinTime(3.0);

void BM_VerifyPoses_Naive(benchmark::State& state) {
  Fixture& fixture = GetFixture();
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  int64_t poses = 0;
  size_t next = 0;
  for (auto _ : state) {
    const VerifyResult result = VerifyPoseNaive(
        fixture.model, fixture.scans[0], fixture.poses[next++ % fixture.poses.size()], fixture.options);
    benchmark::DoNotOptimize(result.confidence);
    ++poses;
  }
  state.SetItemsProcessed(poses);
  state.counters["threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_VerifyPoses_Naive)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->MinTime(3.0);

// The same straightforward implementation in the harness of the fast one: poses in parallel, one per thread
// (each pose's own cast may use the other thread too). The fair wall-clock comparison: BM_VerifyPoses_Naive
// runs one pose at a time, leaving a core idle during its serial KD-tree queries.
void BM_VerifyPoses_NaiveParallel(benchmark::State& state) {
  Fixture& fixture = GetFixture();
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  constexpr int kBatch = 8;
  int64_t poses = 0;
  size_t next = 0;
  for (auto _ : state) {
    std::vector<double> confidence(kBatch);
    ParallelFor(kBatch, [&](int64_t p) {
      confidence[p] = VerifyPoseNaive(fixture.model, fixture.scans[0],
                                      fixture.poses[(next + p) % fixture.poses.size()], fixture.options)
                          .confidence;
    });
    next += kBatch;
    benchmark::DoNotOptimize(confidence.data());
    poses += kBatch;
  }
  state.SetItemsProcessed(poses);
  state.counters["threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_VerifyPoses_NaiveParallel)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->MinTime(3.0);

// Not timed: the two implementations agree (printed once, so the results file can quote it).
void BM_Agreement(benchmark::State& state) {
  Fixture& fixture = GetFixture();
  double max_consistency_difference = 0, max_confidence_difference = 0;
  int64_t rays = 0;
  for (auto _ : state) {
    for (int p = 0; p < 8; ++p) {
      const VerifyResult fast = VerifyPose(fixture.model, fixture.scans, fixture.poses[p], fixture.options);
      const VerifyResult naive =
          VerifyPoseNaive(fixture.model, fixture.scans[0], fixture.poses[p], fixture.options);
      max_consistency_difference =
          std::max(max_consistency_difference, std::abs(fast.consistency - naive.consistency));
      max_confidence_difference =
          std::max(max_confidence_difference, std::abs(fast.confidence - naive.confidence));
      rays += fast.comparable_pairs;
    }
  }
  state.counters["max_consistency_difference"] = max_consistency_difference;
  state.counters["max_confidence_difference"] = max_confidence_difference;
  state.counters["model_triangles"] = static_cast<double>(fixture.model.mesh_in_model.num_triangles());
  state.counters["scan_valid_cells"] = static_cast<double>(fixture.scans[0].num_valid);
}
BENCHMARK(BM_Agreement)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
