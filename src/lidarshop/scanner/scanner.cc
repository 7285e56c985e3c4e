#include "lidarshop/scanner/scanner.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <vector>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scanner/shade.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {
namespace {

using scanner_internal::Band;
using scanner_internal::ObjectData;
using scanner_internal::ShadeSetup;

// One ray's hit into the band's cell k.
inline void StoreHit(int k, float t, unsigned geometry, unsigned primitive, float u, float v, float n_x,
                     float n_y, float n_z, Band* band) {
  band->t[k] = t;
  band->geometry[k] = static_cast<int32_t>(geometry);  // RTC_INVALID_GEOMETRY_ID is -1
  band->primitive[k] = static_cast<int32_t>(primitive);
  band->u[k] = u;
  band->v[k] = v;
  band->n_x[k] = n_x;
  band->n_y[k] = n_y;
  band->n_z[k] = n_z;
}

// Packets of N rays (8 or 16) over tiles of N / 4 rows x 4 columns of the band (coherent flag).
template <int N, typename RayHitN, void (*IntersectN)(const int*, RTCScene, RTCIntersectContext*, RayHitN*)>
void CastPackets(RTCScene rtc_scene, const ShadeSetup& setup, float t_near, float t_far, Band* band) {
  constexpr int kTileRows = N / 4;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RayHitN packet;
  alignas(64) int lane_valid[N];
  for (int i = 0; i < N; ++i) {
    packet.ray.org_x[i] = setup.origin[0];
    packet.ray.org_y[i] = setup.origin[1];
    packet.ray.org_z[i] = setup.origin[2];
    packet.ray.tnear[i] = t_near;
    packet.ray.mask[i] = 0xFFFFFFFFu;
    packet.ray.time[i] = 0.0f;
    packet.ray.flags[i] = 0;
  }
  const int cols = band->cols;
  // Lanes 4 * r .. 4 * r + 3 are columns col0 .. col0 + 3 of the tile's row r: whole tiles move 4 floats
  // at a time between the band's rows and the packet.
  auto copy_lanes = [](float* to, const float* from) { std::memcpy(to, from, 4 * sizeof(float)); };
  for (int tile_row = 0; tile_row < band->rows; tile_row += kTileRows) {
    for (int col0 = 0; col0 < cols; col0 += 4) {
      const bool full = tile_row + kTileRows <= band->rows && col0 + 4 <= cols;
      if (full) {
        for (int i = 0; i < N; ++i) lane_valid[i] = -1;
        for (int r = 0; r < kTileRows; ++r) {
          const int k = (tile_row + r) * cols + col0;
          copy_lanes(packet.ray.dir_x + 4 * r, band->w_x.data() + k);
          copy_lanes(packet.ray.dir_y + 4 * r, band->w_y.data() + k);
          copy_lanes(packet.ray.dir_z + 4 * r, band->w_z.data() + k);
        }
      } else {
        for (int i = 0; i < N; ++i) {
          const int r = tile_row + i / 4, col = col0 + i % 4;
          const bool inside = r < band->rows && col < cols;
          const int k = inside ? r * cols + col : 0;
          lane_valid[i] = inside ? -1 : 0;
          packet.ray.dir_x[i] = band->w_x[k];
          packet.ray.dir_y[i] = band->w_y[k];
          packet.ray.dir_z[i] = band->w_z[k];
        }
      }
      // (Separate loops of constant stores: they vectorize.)
      for (int i = 0; i < N; ++i) packet.ray.tfar[i] = t_far;
      for (int i = 0; i < N; ++i) packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      for (int i = 0; i < N; ++i) packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
      IntersectN(lane_valid, rtc_scene, &context, &packet);
      if (full) {
        for (int r = 0; r < kTileRows; ++r) {
          const int k = (tile_row + r) * cols + col0;
          copy_lanes(band->t.data() + k, packet.ray.tfar + 4 * r);
          std::memcpy(band->geometry.data() + k, packet.hit.geomID + 4 * r, 4 * sizeof(int32_t));
          std::memcpy(band->primitive.data() + k, packet.hit.primID + 4 * r, 4 * sizeof(int32_t));
          copy_lanes(band->u.data() + k, packet.hit.u + 4 * r);
          copy_lanes(band->v.data() + k, packet.hit.v + 4 * r);
          copy_lanes(band->n_x.data() + k, packet.hit.Ng_x + 4 * r);
          copy_lanes(band->n_y.data() + k, packet.hit.Ng_y + 4 * r);
          copy_lanes(band->n_z.data() + k, packet.hit.Ng_z + 4 * r);
        }
        continue;
      }
      for (int i = 0; i < N; ++i) {
        if (lane_valid[i] == 0) continue;
        StoreHit((tile_row + i / 4) * cols + col0 + i % 4, packet.ray.tfar[i], packet.hit.geomID[i],
                 packet.hit.primID[i], packet.hit.u[i], packet.hit.v[i], packet.hit.Ng_x[i],
                 packet.hit.Ng_y[i], packet.hit.Ng_z[i], band);
      }
    }
  }
}

// The band's rays, in 4 x 4 tile order for the stream (coherent flag) or one by one, as RTCRayHit.
void CastRays(RTCScene rtc_scene, const ShadeSetup& setup, bool stream, float t_near, float t_far,
              Band* band) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (stream) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  thread_local std::vector<RTCRayHit> rays;
  rays.resize(std::max(rays.size(), static_cast<size_t>(band->cells())));
  const int cols = band->cols;
  // Visits the band's cells in tile order: f(index in the stream, cell).
  auto for_each_cell = [&](auto&& f) {
    int i = 0;
    for (int col0 = 0; col0 < cols; col0 += 4) {
      const int col_end = std::min(cols, col0 + 4);
      for (int r = 0; r < band->rows; ++r) {
        for (int col = col0; col < col_end; ++col) f(i++, r * cols + col);
      }
    }
  };
  RTCRayHit* stream_rays = rays.data();
  for_each_cell([&](int i, int k) {
    RTCRayHit& ray_hit = stream_rays[i];
    ray_hit.ray.org_x = setup.origin[0];
    ray_hit.ray.org_y = setup.origin[1];
    ray_hit.ray.org_z = setup.origin[2];
    ray_hit.ray.dir_x = band->w_x[k];
    ray_hit.ray.dir_y = band->w_y[k];
    ray_hit.ray.dir_z = band->w_z[k];
    ray_hit.ray.tnear = t_near;
    ray_hit.ray.tfar = t_far;
    ray_hit.ray.mask = 0xFFFFFFFFu;
    ray_hit.ray.flags = 0;
    ray_hit.ray.time = 0.0f;
    ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  });
  if (stream) {
    rtcIntersect1M(rtc_scene, &context, stream_rays, static_cast<unsigned>(band->cells()), sizeof(RTCRayHit));
  } else {
    for (int i = 0; i < band->cells(); ++i) rtcIntersect1(rtc_scene, &context, &stream_rays[i]);
  }
  for_each_cell([&](int i, int k) {
    const RTCRayHit& h = stream_rays[i];
    StoreHit(k, h.ray.tfar, h.hit.geomID, h.hit.primID, h.hit.u, h.hit.v, h.hit.Ng_x, h.hit.Ng_y, h.hit.Ng_z,
             band);
  });
}

void CastBand(RTCScene rtc_scene, const ShadeSetup& setup, CastMethod method, float t_near, float t_far,
              Band* band) {
  switch (method) {
    case CastMethod::kPacket16:
      CastPackets<16, RTCRayHit16, rtcIntersect16>(rtc_scene, setup, t_near, t_far, band);
      return;
    case CastMethod::kPacket8:
      CastPackets<8, RTCRayHit8, rtcIntersect8>(rtc_scene, setup, t_near, t_far, band);
      return;
    case CastMethod::kStream:
    case CastMethod::kSingle:
      CastRays(rtc_scene, setup, method == CastMethod::kStream, t_near, t_far, band);
      return;
  }
}

}  // namespace

struct SyntheticScanner::Impl {
  explicit Impl(const RaycastSceneOptions& options) : raycast(options) {}
  RaycastScene raycast;
  std::vector<ObjectData> objects;
  int64_t num_triangles = 0;
  double build_seconds = 0.0;
};

SyntheticScanner::SyntheticScanner(const SceneDescription& scene, const RaycastSceneOptions& raycast_options)
    : impl_(std::make_unique<Impl>(raycast_options)) {
  Timer timer;
  impl_->objects.resize(scene.objects.size());
  ParallelFor(static_cast<int64_t>(scene.objects.size()),
              [&](int64_t i) { impl_->objects[i] = scanner_internal::MakeObjectData(scene.objects[i]); });
  for (size_t i = 0; i < impl_->objects.size(); ++i) {
    impl_->raycast.AddMesh(impl_->objects[i].mesh_in_world, static_cast<int32_t>(i));
    impl_->num_triangles += static_cast<int64_t>(impl_->objects[i].mesh_in_world.triangles.size());
  }
  impl_->raycast.Commit();
  impl_->build_seconds = timer.Seconds();
}

SyntheticScanner::~SyntheticScanner() = default;
SyntheticScanner::SyntheticScanner(SyntheticScanner&&) noexcept = default;
SyntheticScanner& SyntheticScanner::operator=(SyntheticScanner&&) noexcept = default;

const RaycastScene& SyntheticScanner::raycast_scene() const { return impl_->raycast; }
int64_t SyntheticScanner::num_triangles() const { return impl_->num_triangles; }
double SyntheticScanner::build_seconds() const { return impl_->build_seconds; }

Scan SyntheticScanner::Acquire(const ScannerOptions& options, Progress* progress, ScanStats* stats) const {
  Scan scan;
  AcquireInto(options, &scan, progress, stats);
  return scan;
}

void SyntheticScanner::AcquireInto(const ScannerOptions& options, Scan* scan_out, Progress* progress,
                                   ScanStats* stats) const {
  options.Check();
  const int rows = options.rows, cols = options.columns;
  // Every channel is written for every cell by the loops below, so nothing is pre-filled.
  Scan& scan = *scan_out;
  scan.synthesized.release();
  scan.from_station.release();
  scan.rows = rows;
  scan.cols = cols;
  scan.name = "synthetic";
  scan.grid = options.Grid();
  scan.world_from_scanner = options.WorldFromScanner();
  scan.direction.create(rows, cols, CV_32FC3);
  scan.valid.create(rows, cols, CV_8U);
  scan.range.create(rows, cols, CV_32F);
  scan.point.create(rows, cols, CV_32FC3);
  scan.intensity.create(rows, cols, CV_32F);
  scan.color.create(rows, cols, CV_8UC3);
  scan.label.create(rows, cols, CV_32S);
  scan.normal.create(rows, cols, CV_32FC3);
  scan.true_range.create(rows, cols, CV_32F);

  const ShadeSetup setup(impl_->objects, options, scan.grid, scan.world_from_scanner);
  const float t_near = static_cast<float>(options.min_range_m);
  const float t_far = static_cast<float>(options.max_range_m);
  RTCScene rtc_scene = static_cast<RTCScene>(impl_->raycast.native_scene());

  ScanStats local_stats;
  local_stats.rays = scan.num_cells();
  std::atomic<int64_t> returns{0};
  std::atomic<int64_t> cast_nanoseconds{0}, shade_nanoseconds{0};  // summed over threads
  Timer timer;
  // One loop over all bands of 4 rows (no barriers between chunks of rows: a thread never waits for
  // another); progress advances as ranges of bands finish.
  const int bands = (rows + 3) / 4;
  ParallelForRange(bands, [&](int64_t band_begin, int64_t band_end) {
    thread_local Band band;
    band.Resize(cols);
    int64_t band_returns = 0;
    double cast_time = 0, shade_time = 0;
    for (int64_t band_index = band_begin; band_index < band_end; ++band_index) {
      const int row0 = static_cast<int>(band_index) * 4;
      Timer stage;
      PrepareBand(setup, row0, std::min(rows, row0 + 4) - row0, &band, &scan, options.simd_path);
      CastBand(rtc_scene, setup, options.cast_method, t_near, t_far, &band);
      cast_time += stage.Seconds();
      stage.Restart();
      band_returns += ShadeBand(setup, &band, &scan, options.simd_path);
      shade_time += stage.Seconds();
    }
    returns += band_returns;
    cast_nanoseconds += static_cast<int64_t>(1e9 * cast_time);
    shade_nanoseconds += static_cast<int64_t>(1e9 * shade_time);
    Advance(progress, std::min<int64_t>(rows, band_end * 4) - band_begin * 4);
  });
  const double seconds = timer.Seconds();
  const double busy = static_cast<double>(cast_nanoseconds + shade_nanoseconds);
  local_stats.cast_seconds = busy > 0 ? seconds * static_cast<double>(cast_nanoseconds) / busy : seconds;
  local_stats.shade_seconds = seconds - local_stats.cast_seconds;
  local_stats.returns = returns.load();
  if (stats != nullptr) *stats = local_stats;
}

Scan SynthesizeScan(const SceneDescription& scene, Progress* progress) {
  const SyntheticScanner scanner(scene);
  return scanner.Acquire(scene.scanner, progress);
}

}  // namespace lidarshop
