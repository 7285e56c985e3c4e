// Speed of the point-set tools (pointset/*.h) on a synthetic 1 M-point cloud (a 40 m ground with 5 mm noise,
// four 2 m boxes, 3 % uniform outliers), on 1 and 2 threads. The side-by-side with Open3D on the same kind of
// cloud is bench/pointset_peers.py; bench/results/pointset.md keeps both.
//
//   ninja -C build/release pointset_bench && build/release/bench/pointset_bench
#include <random>

#include <benchmark/benchmark.h>

#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

const PointCloud& Cloud() {
  static const PointCloud cloud = [] {
    std::mt19937_64 random(17);
    std::uniform_real_distribution<float> ground(-20.0f, 20.0f), unit(-1.0f, 1.0f), height(0.0f, 2.0f);
    std::normal_distribution<float> noise(0.0f, 0.005f);
    PointCloud c;
    const int n = 1000000;
    for (int i = 0; i < n * 72 / 100; ++i)
      c.points.emplace_back(ground(random), ground(random), noise(random));
    const float centres[4][2] = {{-6, 5}, {4, 8}, {8, -5}, {-5, -7}};
    for (int i = 0; i < n / 4; ++i) {
      const float* centre = centres[i % 4];
      const int face = static_cast<int>(random() % 5);
      Eigen::Vector3f p(unit(random), unit(random), height(random));
      if (face < 2) p.x() = face == 0 ? -1.0f : 1.0f;
      if (face == 2 || face == 3) p.y() = face == 2 ? -1.0f : 1.0f;
      if (face == 4) p.z() = 2.0f;
      c.points.emplace_back(p.x() + centre[0], p.y() + centre[1], p.z());
    }
    while (c.points.size() < static_cast<size_t>(n))
      c.points.emplace_back(ground(random), ground(random), 3.0f * height(random));
    return c;
  }();
  return cloud;
}

void BM_Normals(benchmark::State& state) {
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(EstimateNormals(Cloud(), {.neighbors = 20}));
}
void BM_StatisticalOutliers(benchmark::State& state) {
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(StatisticalOutlierInliers(Cloud(), {.neighbors = 20}));
}
void BM_RansacPlane(benchmark::State& state) {
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(FitPlaneRansac(Cloud(), {.distance_threshold_m = 0.01}));
}
void BM_EuclideanClusters(benchmark::State& state) {
  const ThreadLimit limit(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(EuclideanClusters(Cloud(), {.radius_m = 0.1}));
}
void BM_VoxelDownsample(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(VoxelDownsample(Cloud(), 0.05));
}

BENCHMARK(BM_Normals)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_StatisticalOutliers)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK(BM_RansacPlane)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_EuclideanClusters)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_VoxelDownsample)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
