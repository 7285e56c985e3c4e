// Colouring a station from its own cube map (issue 32, item 6), and the z-buffer behind it: the scan mesh
// rasterized into each photo's buffer against Embree's rays (bench/results/recolor.md).
//
//   recolor_bench --benchmark_filter=Station                       # 10 M returns, 6 x 2048² faces
//   recolor_bench --benchmark_filter=StationRecolor/750            # 0.6 M returns, seconds
//   recolor_bench --benchmark_filter=DistanceBuffer
//
// The station is the built-in parking lot (SYNTHETIC: lidarshop's own scene), scanned on a rows x columns grid
// with the scanner's noise, and its cube map rendered from 0.15 m above the scanner, as
// `lidarshop scan parking_lot --rows R --columns C --photos cube --photo-size P` writes them.
#include <chrono>
#include <map>
#include <memory>
#include <tuple>

#include <benchmark/benchmark.h>

#include "lidarshop/recolor/distance_raster.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/recolor/visibility.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/station_photos.h"

namespace lidarshop {
namespace {

struct Station {
  Scan scan;
  std::vector<CameraPhoto> photos;
};

const Station& CachedStation(int rows, int columns, int face_px) {
  static std::map<std::tuple<int, int, int>, std::unique_ptr<Station>> cache;
  auto& slot = cache[{rows, columns, face_px}];
  if (!slot) {
    slot = std::make_unique<Station>();
    const SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/scenes/parking_lot.json");
    ScannerOptions scanner = scene.scanner;
    scanner.rows = rows;
    scanner.columns = columns;
    slot->scan = SyntheticScanner(scene).Acquire(scanner);
    StationPhotoOptions options;
    options.kind = StationPhotoKind::kCube;
    options.size_px = face_px;
    for (StationPhoto& photo : RenderStationPhotos(scene, scanner, options))
      slot->photos.push_back({photo.image, photo.camera});
  }
  return *slot;
}

// Args: rows, columns, face pixels.
void BM_StationRecolor(benchmark::State& state) {
  const Station& station = CachedStation(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                                         static_cast<int>(state.range(2)));
  PhotosRecolorResult result;
  for (auto _ : state) {
    result = RecolorFromPhotos(station.scan, station.photos);
    benchmark::DoNotOptimize(result.coloured);
  }
  state.counters["returns"] = static_cast<double>(result.returns);
  state.counters["coloured"] = static_cast<double>(result.coloured);
  state.counters["scene_s"] = result.scene_seconds;
  state.counters["visibility_s"] = result.visibility_seconds;
  state.counters["blend_s"] = result.blend_seconds;
  state.counters["zbuffer_s"] = result.zbuffer_seconds;
  state.counters["projection_s"] = result.projection_seconds;
  state.counters["choice_s"] = result.choice_seconds;
  state.counters["gain_s"] = result.gain_seconds;
  state.counters["output_s"] = result.output_seconds;
  state.counters["total_s"] = result.total_seconds;
  state.counters["cpu_s"] = result.cpu_seconds;  // the process's CPU time, every thread
}
BENCHMARK(BM_StationRecolor)
    ->Args({3000, 5000, 2048})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK(BM_StationRecolor)
    ->Args({1500, 2500, 1024})
    ->Unit(benchmark::kSecond)
    ->Iterations(2)
    ->UseRealTime();
BENCHMARK(BM_StationRecolor)
    ->Args({750, 1250, 512})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

// One face's z-buffer (the front face) of a 1500 x 2500 station: Embree (the BVH built once for all photos,
// then every pixel's ray cast) against the raster (no BVH).
void BM_DistanceBufferCast(benchmark::State& state) {
  const Station& station = CachedStation(1500, 2500, 1024);
  const recolor_internal::OcclusionScene occlusion =
      recolor_internal::BuildOcclusionScene(station.scan, RecolorOptions());
  double build_s = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    RaycastScene scene;
    scene.AddMesh(occlusion.mesh, 0);
    if (!occlusion.skirts.empty()) scene.AddMesh(occlusion.skirts, 1);
    scene.Commit();
    build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    benchmark::DoNotOptimize(recolor_internal::CastDistanceBuffer(scene, station.photos[0].camera, 1.0));
  }
  state.counters["bvh_build_s"] = build_s;
}
BENCHMARK(BM_DistanceBufferCast)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

void BM_DistanceBufferRaster(benchmark::State& state) {
  const Station& station = CachedStation(1500, 2500, 1024);
  const recolor_internal::OcclusionScene occlusion =
      recolor_internal::BuildOcclusionScene(station.scan, RecolorOptions());
  int64_t cast = 0;
  for (auto _ : state) {
    const recolor_internal::DistanceBuffer buffer = recolor_internal::RasterDistanceBuffer(
        occlusion.mesh, occlusion.skirts, station.photos[0].camera, 1.0);
    cast = buffer.cast_triangles;
    benchmark::DoNotOptimize(buffer.distance.data);
  }
  state.counters["triangles"] =
      static_cast<double>(occlusion.mesh.triangles.size() + occlusion.skirts.triangles.size());
  state.counters["cast_triangles"] = static_cast<double>(cast);
}
BENCHMARK(BM_DistanceBufferRaster)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
