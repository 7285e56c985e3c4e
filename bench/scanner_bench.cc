// The synthetic scanner against raw Embree on the same mesh and the same rays, in one run.
//
// Scene: the built-in parking lot with its three cars refined to ~220,000 triangles each (>= 500,000
// triangles in all), gravel and grass textures, a façade; a 1000 x 1000 scan with noise, all outputs on
// (range, point, normal, colour with textures, label, intensity, true range).
//
//   BM_Scanner/<quality>/<robust>    lidarshop's SyntheticScanner::Acquire: casting + every output channel
//   BM_Textures/<kind>               the procedural textures alone, 1,000,000 points per iteration
//   BM_ScanMesh                      ScanToMesh of the 1000 x 1000 scan (the optional mesh output)
//   BM_EmbreeSingle                  a plain loop of rtcIntersect1 per ray over TBB chunks, writing t_hit,
//                                    ids, normal and uv (as Open3D's RaycastingScene::CastRays does per ray)
//   BM_EmbreePacket16                rtcIntersect16 over 4 x 4 tiles (coherent flag)
//   BM_EmbreePacket8                 rtcIntersect8 over 2 x 4 tiles (coherent flag)
//   BM_EmbreeStream                  rtcIntersect1M over bands of 4 rows in tile order (coherent flag)
// items_per_second = rays per second. The raw paths use the scanner's own Embree scene (same BVH).
#include <embree3/rtcore.h>

#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/texture.h"

namespace lidarshop {
namespace {

constexpr int kRows = 1000;
constexpr int kCols = 1000;

SceneDescription BenchScene() {
  SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/scenes/parking_lot.json");
  for (auto& object : scene.objects) {
    if (object.name == "sedan" || object.name == "hatchback" || object.name == "van") {
      object.mesh = SubdivideMesh(object.mesh, 4);
    }
  }
  scene.scanner.rows = kRows;
  scene.scanner.columns = kCols;
  return scene;
}

const SceneDescription& Scene() {
  static const SceneDescription scene = BenchScene();
  return scene;
}

// One scanner per (build quality, robust) configuration, built once.
const SyntheticScanner& ScannerFor(const std::string& quality, bool robust) {
  static std::map<std::pair<std::string, bool>, std::unique_ptr<SyntheticScanner>> scanners;
  auto& scanner = scanners[{quality, robust}];
  if (!scanner) {
    RaycastSceneOptions options;
    options.build_quality = quality;
    options.robust = robust;
    scanner = std::make_unique<SyntheticScanner>(Scene(), options);
  }
  return *scanner;
}

const char* kQualities[] = {"low", "medium", "high"};

void BM_Scanner(benchmark::State& state) {
  const SyntheticScanner& scanner = ScannerFor(kQualities[state.range(0)], state.range(1) != 0);
  state.SetLabel(fmt::format("{} triangles, quality {}, robust {}, build {:.3f} s", scanner.num_triangles(),
                             kQualities[state.range(0)], state.range(1), scanner.build_seconds()));
  int64_t returns = 0;
  double cast_seconds = 0, shade_seconds = 0;
  Scan scan;  // reused across iterations, like the raw paths' output buffers
  for (auto _ : state) {
    ScanStats stats;
    scanner.AcquireInto(Scene().scanner, &scan, nullptr, &stats);
    returns = stats.returns;
    cast_seconds += stats.cast_seconds;
    shade_seconds += stats.shade_seconds;
    benchmark::DoNotOptimize(scan.point.data);
  }
  state.counters["returns"] = static_cast<double>(returns);
  state.counters["cast_ms"] = 1e3 * cast_seconds / state.iterations();
  state.counters["shade_ms"] = 1e3 * shade_seconds / state.iterations();
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}
BENCHMARK(BM_Scanner)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"quality", "robust"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

// Where the shading time goes: 0 = everything, 1 = no noise, 2 = no procedural textures, 3 = neither;
// 4 = everything with a fresh Scan per iteration (Acquire: page faults of new buffers included);
// 5..7 = everything with CastMethod kPacket8, kStream, kSingle.
void BM_ScannerParts(benchmark::State& state) {
  static std::map<int, std::unique_ptr<SyntheticScanner>> scanners;
  const int variant = static_cast<int>(state.range(0));
  SceneDescription scene = Scene();
  if (variant == 5) scene.scanner.cast_method = CastMethod::kPacket8;
  if (variant == 6) scene.scanner.cast_method = CastMethod::kStream;
  if (variant == 7) scene.scanner.cast_method = CastMethod::kSingle;
  if (variant < 4 && (variant & 2)) {
    for (auto& object : scene.objects) object.material.texture = TextureKind::kNone;
  }
  if (variant < 4 && (variant & 1))
    scene.scanner.los_noise_sigma_m = scene.scanner.orthogonal_noise_sigma_m = 0;
  auto& scanner = scanners[variant];
  if (!scanner) scanner = std::make_unique<SyntheticScanner>(scene);
  double cast_seconds = 0, shade_seconds = 0;
  Scan scan;
  for (auto _ : state) {
    ScanStats stats;
    if (variant == 4) {
      scan = scanner->Acquire(scene.scanner, nullptr, &stats);
    } else {
      scanner->AcquireInto(scene.scanner, &scan, nullptr, &stats);
    }
    cast_seconds += stats.cast_seconds;
    shade_seconds += stats.shade_seconds;
  }
  state.counters["cast_ms"] = 1e3 * cast_seconds / state.iterations();
  state.counters["shade_ms"] = 1e3 * shade_seconds / state.iterations();
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}
BENCHMARK(BM_ScannerParts)->DenseRange(0, 7)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// Procedural textures alone: EvaluateTextures over 1,000,000 points of a 10 x 10 m patch, footprints from
// 0 to 6 cm (near to far ground of the bench scan), for each kind; items = points.
void BM_Textures(benchmark::State& state) {
  const auto kind = static_cast<TextureKind>(state.range(0));
  constexpr int kPoints = 1000000;
  std::vector<float> u(kPoints), v(kPoints), footprint(kPoints);
  std::vector<uint32_t> base(kPoints, PackRgb(DefaultTextureColor(kind))), rgb(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    u[i] = 0.01f * static_cast<float>(i % 1000);
    v[i] = 0.01f * static_cast<float>(i / 1000);
    footprint[i] = 0.06f * static_cast<float>(i / 1000) / 1000.0f;
  }
  for (auto _ : state) {
    EvaluateTextures(kind, 1.0f, kPoints, u.data(), v.data(), footprint.data(), base.data(), rgb.data());
    benchmark::DoNotOptimize(rgb.data());
  }
  state.SetLabel(ToString(kind));
  state.SetItemsProcessed(state.iterations() * kPoints);
}
BENCHMARK(BM_Textures)
    ->DenseRange(static_cast<int>(TextureKind::kChecker), static_cast<int>(TextureKind::kBrick))
    ->Unit(benchmark::kMillisecond);

void BM_ScanMesh(benchmark::State& state) {
  const Scan scan = ScannerFor("medium", true).Acquire(Scene().scanner);
  size_t triangles = 0;
  for (auto _ : state) {
    const TriangleMesh mesh = ScanToMesh(scan);
    triangles = mesh.triangles.size();
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}
BENCHMARK(BM_ScanMesh)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// The scanner's rays in the world frame, image row-major.
struct WorldRays {
  Eigen::Vector3f origin;
  std::vector<Eigen::Vector3f> directions;
};

// Ray `index` of `rays` as a fresh RTCRayHit (what the single-ray and the stream paths cast).
void FillRayHit(const WorldRays& rays, size_t index, RTCRayHit* rh) {
  rh->ray.org_x = rays.origin.x();
  rh->ray.org_y = rays.origin.y();
  rh->ray.org_z = rays.origin.z();
  rh->ray.dir_x = rays.directions[index].x();
  rh->ray.dir_y = rays.directions[index].y();
  rh->ray.dir_z = rays.directions[index].z();
  rh->ray.tnear = 0.0f;
  rh->ray.tfar = 120.0f;
  rh->ray.mask = 0xFFFFFFFFu;
  rh->ray.flags = 0;
  rh->ray.time = 0;
  rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

const WorldRays& Rays() {
  static const WorldRays rays = [] {
    WorldRays result;
    const ScannerOptions& options = Scene().scanner;
    const cv::Mat directions = DirectionsFromGrid(options.Grid());
    const Eigen::Matrix3f rotation = options.WorldFromScanner().topLeftCorner<3, 3>().cast<float>();
    result.origin = options.position.cast<float>();
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        const cv::Vec3f d = directions.at<cv::Vec3f>(r, c);
        result.directions.push_back(rotation * Eigen::Vector3f(d[0], d[1], d[2]));
      }
    }
    return result;
  }();
  return rays;
}

// The outputs Open3D's cast_rays returns, one entry per ray.
struct RawOutputs {
  std::vector<float> t_hit = std::vector<float>(kRows * kCols);
  std::vector<uint32_t> geometry_id = std::vector<uint32_t>(kRows * kCols);
  std::vector<uint32_t> primitive_id = std::vector<uint32_t>(kRows * kCols);
  std::vector<Eigen::Vector3f> normal = std::vector<Eigen::Vector3f>(kRows * kCols);
  std::vector<Eigen::Vector2f> uv = std::vector<Eigen::Vector2f>(kRows * kCols);

  void Write(size_t i, float t, unsigned geometry, unsigned primitive, float nx, float ny, float nz, float u,
             float v) {
    t_hit[i] = t;
    geometry_id[i] = geometry;
    primitive_id[i] = primitive;
    normal[i] = Eigen::Vector3f(nx, ny, nz).normalized();
    uv[i] = Eigen::Vector2f(u, v);
  }
};

RTCScene NativeScene(const benchmark::State& state) {
  return static_cast<RTCScene>(
      ScannerFor(kQualities[state.range(0)], state.range(1) != 0).raycast_scene().native_scene());
}

void BM_EmbreeSingle(benchmark::State& state) {
  RTCScene scene = NativeScene(state);
  const WorldRays& rays = Rays();
  RawOutputs out;
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.directions.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& range) {
                        RTCIntersectContext context;
                        rtcInitIntersectContext(&context);
                        RTCRayHit rh;
                        for (size_t i = range.begin(); i < range.end(); ++i) {
                          FillRayHit(rays, i, &rh);
                          rtcIntersect1(scene, &context, &rh);
                          out.Write(i, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.Ng_x, rh.hit.Ng_y,
                                    rh.hit.Ng_z, rh.hit.u, rh.hit.v);
                        }
                      });
    benchmark::DoNotOptimize(out.t_hit.data());
  }
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}

// Packets of N rays (8 or 16) on tiles of N / 4 rows x 4 columns: coherent rays, as the scanner casts them.
template <int N, typename RayHitN, void (*IntersectN)(const int*, RTCScene, RTCIntersectContext*, RayHitN*)>
void BM_EmbreePacket(benchmark::State& state) {
  constexpr int kTileRows = N / 4;
  RTCScene scene = NativeScene(state);
  const WorldRays& rays = Rays();
  RawOutputs out;
  for (auto _ : state) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, kRows / kTileRows), [&](const tbb::blocked_range<int>& tiles) {
          RTCIntersectContext context;
          rtcInitIntersectContext(&context);
          context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
          alignas(64) RayHitN packet;
          alignas(64) int valid[N];
          for (int i = 0; i < N; ++i) valid[i] = -1;
          for (int tile_row = tiles.begin(); tile_row < tiles.end(); ++tile_row) {
            for (int col0 = 0; col0 < kCols; col0 += 4) {
              for (int i = 0; i < N; ++i) {
                const size_t index = static_cast<size_t>(tile_row * kTileRows + i / 4) * kCols + col0 + i % 4;
                packet.ray.org_x[i] = rays.origin.x();
                packet.ray.org_y[i] = rays.origin.y();
                packet.ray.org_z[i] = rays.origin.z();
                packet.ray.dir_x[i] = rays.directions[index].x();
                packet.ray.dir_y[i] = rays.directions[index].y();
                packet.ray.dir_z[i] = rays.directions[index].z();
                packet.ray.tnear[i] = 0.0f;
                packet.ray.tfar[i] = 120.0f;
                packet.ray.mask[i] = 0xFFFFFFFFu;
                packet.ray.flags[i] = 0;
                packet.ray.time[i] = 0;
                packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
              }
              IntersectN(valid, scene, &context, &packet);
              for (int i = 0; i < N; ++i) {
                const size_t index = static_cast<size_t>(tile_row * kTileRows + i / 4) * kCols + col0 + i % 4;
                out.Write(index, packet.ray.tfar[i], packet.hit.geomID[i], packet.hit.primID[i],
                          packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i], packet.hit.u[i],
                          packet.hit.v[i]);
              }
            }
          }
        });
    benchmark::DoNotOptimize(out.t_hit.data());
  }
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}

void BM_EmbreePacket16(benchmark::State& state) { BM_EmbreePacket<16, RTCRayHit16, rtcIntersect16>(state); }
void BM_EmbreePacket8(benchmark::State& state) { BM_EmbreePacket<8, RTCRayHit8, rtcIntersect8>(state); }

void BM_EmbreeStream(benchmark::State& state) {
  RTCScene scene = NativeScene(state);
  const WorldRays& rays = Rays();
  RawOutputs out;
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<int>(0, kRows / 4), [&](const tbb::blocked_range<int>& bands) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      std::vector<RTCRayHit> stream(4 * kCols);
      std::vector<size_t> index_of(4 * kCols);
      for (int band = bands.begin(); band < bands.end(); ++band) {
        size_t k = 0;
        for (int col0 = 0; col0 < kCols; col0 += 4) {
          for (int i = 0; i < 16; ++i, ++k) {
            const size_t index = static_cast<size_t>(band * 4 + i / 4) * kCols + col0 + i % 4;
            FillRayHit(rays, index, &stream[k]);
            index_of[k] = index;
          }
        }
        rtcIntersect1M(scene, &context, stream.data(), static_cast<unsigned>(k), sizeof(RTCRayHit));
        for (size_t j = 0; j < k; ++j) {
          const RTCRayHit& rh = stream[j];
          out.Write(index_of[j], rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.Ng_x, rh.hit.Ng_y,
                    rh.hit.Ng_z, rh.hit.u, rh.hit.v);
        }
      }
    });
    benchmark::DoNotOptimize(out.t_hit.data());
  }
  state.SetItemsProcessed(state.iterations() * kRows * kCols);
}

BENCHMARK(BM_EmbreeSingle)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"quality", "robust"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_EmbreePacket16)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"quality", "robust"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_EmbreePacket8)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"quality", "robust"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK(BM_EmbreeStream)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"quality", "robust"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
