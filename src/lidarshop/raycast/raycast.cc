#include "lidarshop/raycast/raycast.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

struct RaycastScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  bool committed = false;
  // Embree's geometry ids are dense from 0; the user's ids are mapped through this table.
  std::vector<int32_t> user_id_of_geometry;
  RTCBuildQuality build_quality = RTC_BUILD_QUALITY_MEDIUM;

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

namespace {

void FillRayHit(const Ray& ray, RTCRayHit* ray_hit) {
  ray_hit->ray.org_x = ray.origin.x();
  ray_hit->ray.org_y = ray.origin.y();
  ray_hit->ray.org_z = ray.origin.z();
  ray_hit->ray.dir_x = ray.direction.x();
  ray_hit->ray.dir_y = ray.direction.y();
  ray_hit->ray.dir_z = ray.direction.z();
  ray_hit->ray.tnear = ray.t_near;
  ray_hit->ray.tfar = ray.t_far;
  ray_hit->ray.mask = 0xFFFFFFFFu;
  ray_hit->ray.flags = 0;
  ray_hit->ray.time = 0.0f;
  ray_hit->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  ray_hit->hit.primID = RTC_INVALID_GEOMETRY_ID;
  ray_hit->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace

void RaycastSceneOptions::Check() const { Validate(*this); }

RaycastScene::RaycastScene() : RaycastScene(RaycastSceneOptions()) {}

RaycastScene::RaycastScene(const RaycastSceneOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  impl_->build_quality = options.build_quality == "low"    ? RTC_BUILD_QUALITY_LOW
                         : options.build_quality == "high" ? RTC_BUILD_QUALITY_HIGH
                                                           : RTC_BUILD_QUALITY_MEDIUM;
  rtcSetSceneBuildQuality(impl_->scene, impl_->build_quality);
  int flags = RTC_SCENE_FLAG_NONE;
  if (options.robust) flags |= RTC_SCENE_FLAG_ROBUST;
  if (options.compact) flags |= RTC_SCENE_FLAG_COMPACT;
  rtcSetSceneFlags(impl_->scene, static_cast<RTCSceneFlags>(flags));
}

RaycastScene::~RaycastScene() = default;
RaycastScene::RaycastScene(RaycastScene&&) noexcept = default;
RaycastScene& RaycastScene::operator=(RaycastScene&&) noexcept = default;

void RaycastScene::AddMesh(const TriangleMesh& mesh, int32_t id) {
  if (impl_->committed) throw std::logic_error("RaycastScene::AddMesh after Commit");
  if (id < 0) throw std::invalid_argument(fmt::format("RaycastScene::AddMesh: id must be >= 0, got {}", id));
  for (int32_t existing : impl_->user_id_of_geometry) {
    if (existing == id)
      throw std::invalid_argument(fmt::format("RaycastScene::AddMesh: id {} used twice", id));
  }
  ValidateMesh(mesh, fmt::format("mesh {}", id));
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads vertex buffers 16 bytes at a time: stride 12 with one padding float at the end.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size() + 1));
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    vertices[3 * v + 0] = mesh.vertices[v].x();
    vertices[3 * v + 1] = mesh.vertices[v].y();
    vertices[3 * v + 2] = mesh.vertices[v].z();
  }
  vertices[3 * mesh.vertices.size() + 0] = vertices[3 * mesh.vertices.size() + 1] =
      vertices[3 * mesh.vertices.size() + 2] = 0.0f;
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), mesh.triangles.size()));
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    for (int corner = 0; corner < 3; ++corner) indices[3 * f + corner] = mesh.triangles[f][corner];
  }
  rtcSetGeometryBuildQuality(geometry, impl_->build_quality);
  rtcCommitGeometry(geometry);
  const unsigned geometry_id = rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  if (geometry_id != impl_->user_id_of_geometry.size())
    throw std::logic_error("Embree geometry ids not dense");
  impl_->user_id_of_geometry.push_back(id);
}

void RaycastScene::Commit() {
  if (impl_->committed) return;
  rtcCommitScene(impl_->scene);
  impl_->committed = true;
}

bool RaycastScene::committed() const { return impl_->committed; }
int RaycastScene::num_meshes() const { return static_cast<int>(impl_->user_id_of_geometry.size()); }
void* RaycastScene::native_scene() const { return impl_->scene; }

void RaycastScene::CastSerial(std::span<const Ray> rays, std::span<RayHit> hits) const {
  if (!impl_->committed) throw std::logic_error("RaycastScene: cast before Commit");
  if (hits.size() != rays.size())
    throw std::invalid_argument("RaycastScene::Cast: rays and hits differ in size");
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit ray_hit;
  for (size_t i = 0; i < rays.size(); ++i) {
    FillRayHit(rays[i], &ray_hit);
    rtcIntersect1(impl_->scene, &context, &ray_hit);
    RayHit& hit = hits[i];
    if (ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      hit = RayHit();
      continue;
    }
    hit.t_hit = ray_hit.ray.tfar;
    hit.geometry_id = impl_->user_id_of_geometry[ray_hit.hit.geomID];
    hit.primitive_id = static_cast<int32_t>(ray_hit.hit.primID);
    hit.normal = Eigen::Vector3f(ray_hit.hit.Ng_x, ray_hit.hit.Ng_y, ray_hit.hit.Ng_z).normalized();
    hit.u = ray_hit.hit.u;
    hit.v = ray_hit.hit.v;
  }
}

void RaycastScene::Cast(std::span<const Ray> rays, std::span<RayHit> hits) const {
  if (hits.size() != rays.size())
    throw std::invalid_argument("RaycastScene::Cast: rays and hits differ in size");
  ParallelForRange(
      static_cast<int64_t>(rays.size()),
      [&](int64_t begin, int64_t end) {
        CastSerial(rays.subspan(begin, end - begin), hits.subspan(begin, end - begin));
      },
      1024);
}

void RaycastScene::Occluded(std::span<const Ray> rays, std::span<uint8_t> occluded) const {
  if (!impl_->committed) throw std::logic_error("RaycastScene: cast before Commit");
  if (occluded.size() != rays.size()) throw std::invalid_argument("RaycastScene::Occluded: size mismatch");
  ParallelForRange(
      static_cast<int64_t>(rays.size()),
      [&](int64_t begin, int64_t end) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit ray_hit;
        for (int64_t i = begin; i < end; ++i) {
          FillRayHit(rays[i], &ray_hit);
          rtcOccluded1(impl_->scene, &context, &ray_hit.ray);
          occluded[i] = ray_hit.ray.tfar < 0 ? 1 : 0;  // Embree sets tfar = -inf on occlusion
        }
      },
      1024);
}

RayHitImages RaycastScene::CastImage(const Eigen::Vector3f& origin, const cv::Mat& directions, float t_near,
                                     float t_far) const {
  Eigen::Matrix4d world_from_sensor = Eigen::Matrix4d::Identity();
  world_from_sensor.topRightCorner<3, 1>() = origin.cast<double>();
  return CastImage(world_from_sensor, directions, t_near, t_far, CastMethod::kPacket16);
}

namespace {

// Image rows are cast in bands of kTileRows; packets are kTileRows x kTileCols tiles of neighbouring cells,
// whose rays are nearly parallel, so Embree's packet traversal visits the same BVH nodes for all 16.
constexpr int kTileRows = 4;
constexpr int kTileCols = 4;

// Writes hits into the images through raw pointers (the hot loop of every cast).
struct HitWriter {
  const int32_t* user_id_of_geometry;
  float* t_hit;
  int32_t* geometry_id;
  int32_t* primitive_id;
  float* normal;                                          // 3 per cell
  float* barycentric;                                     // 2 per cell
  size_t t_step, id_step, normal_step, barycentric_step;  // row steps in elements

  explicit HitWriter(const int32_t* ids, RayHitImages& images)
      : user_id_of_geometry(ids),
        t_hit(images.t_hit.ptr<float>()),
        geometry_id(images.geometry_id.ptr<int32_t>()),
        primitive_id(images.primitive_id.ptr<int32_t>()),
        normal(images.normal.ptr<float>()),
        barycentric(images.barycentric.ptr<float>()),
        t_step(images.t_hit.step1()),
        id_step(images.geometry_id.step1()),
        normal_step(images.normal.step1()),
        barycentric_step(images.barycentric.step1()) {}

  inline __attribute__((always_inline)) void Write(int row, int col, float t, unsigned geometry,
                                                   unsigned primitive, float nx, float ny, float nz, float u,
                                                   float v) const {
    const size_t id_index = row * id_step + col;
    float* n = normal + row * normal_step + 3 * col;
    float* uv = barycentric + row * barycentric_step + 2 * col;
    if (geometry == RTC_INVALID_GEOMETRY_ID) {
      t_hit[row * t_step + col] = std::numeric_limits<float>::infinity();
      geometry_id[id_index] = kInvalidId;
      primitive_id[id_index] = kInvalidId;
      n[0] = n[1] = n[2] = 0.0f;
      uv[0] = uv[1] = 0.0f;
      return;
    }
    t_hit[row * t_step + col] = t;
    geometry_id[id_index] = user_id_of_geometry[geometry];
    primitive_id[id_index] = static_cast<int32_t>(primitive);
    const float inverse_norm = 1.0f / std::sqrt(nx * nx + ny * ny + nz * nz);
    n[0] = nx * inverse_norm;
    n[1] = ny * inverse_norm;
    n[2] = nz * inverse_norm;
    uv[0] = u;
    uv[1] = v;
  }
};

}  // namespace

RayHitImages RaycastScene::CastImage(const Eigen::Matrix4d& world_from_sensor,
                                     const cv::Mat& directions_in_sensor, float t_near, float t_far,
                                     CastMethod method) const {
  RayHitImages images;
  CastImage(world_from_sensor, directions_in_sensor, t_near, t_far, method, &images);
  return images;
}

void RaycastScene::CastImage(const Eigen::Matrix4d& world_from_sensor, const cv::Mat& directions_in_sensor,
                             float t_near, float t_far, CastMethod method, RayHitImages* hits) const {
  if (!impl_->committed) throw std::logic_error("RaycastScene: cast before Commit");
  if (directions_in_sensor.type() != CV_32FC3) {
    throw std::invalid_argument("RaycastScene::CastImage: directions must be CV_32FC3");
  }
  const int rows = directions_in_sensor.rows;
  const int cols = directions_in_sensor.cols;
  RayHitImages& images = *hits;
  images.t_hit.create(rows, cols, CV_32F);
  images.geometry_id.create(rows, cols, CV_32S);
  images.primitive_id.create(rows, cols, CV_32S);
  images.normal.create(rows, cols, CV_32FC3);
  images.barycentric.create(rows, cols, CV_32FC2);
  if (rows == 0 || cols == 0) return;
  const Eigen::Matrix3f rotation = world_from_sensor.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f origin = world_from_sensor.topRightCorner<3, 1>().cast<float>();
  const HitWriter writer(impl_->user_id_of_geometry.data(), images);
  RTCScene scene = impl_->scene;
  const float r00 = rotation(0, 0), r01 = rotation(0, 1), r02 = rotation(0, 2);
  const float r10 = rotation(1, 0), r11 = rotation(1, 1), r12 = rotation(1, 2);
  const float r20 = rotation(2, 0), r21 = rotation(2, 1), r22 = rotation(2, 2);
  auto direction_at = [&](int row, int col) __attribute__((always_inline)) {
    const float* d = directions_in_sensor.ptr<float>(row) + 3 * col;
    return Eigen::Vector3f(r00 * d[0] + r01 * d[1] + r02 * d[2], r10 * d[0] + r11 * d[1] + r12 * d[2],
                           r20 * d[0] + r21 * d[1] + r22 * d[2]);
  };
  const int bands = (rows + kTileRows - 1) / kTileRows;
  ParallelForRange(bands, [&](int64_t band_begin, int64_t band_end) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (method != CastMethod::kSingle) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    std::vector<RTCRayHit> stream;
    std::vector<std::pair<int, int>> stream_cells;
    for (int64_t band = band_begin; band < band_end; ++band) {
      const int row0 = static_cast<int>(band) * kTileRows;
      const int row1 = std::min(rows, row0 + kTileRows);
      if (method == CastMethod::kSingle) {
        RTCRayHit ray_hit;
        for (int row = row0; row < row1; ++row) {
          for (int col = 0; col < cols; ++col) {
            const Eigen::Vector3f d = direction_at(row, col);
            FillRayHit(Ray{origin, d, t_near, t_far}, &ray_hit);
            rtcIntersect1(scene, &context, &ray_hit);
            writer.Write(row, col, ray_hit.ray.tfar, ray_hit.hit.geomID, ray_hit.hit.primID, ray_hit.hit.Ng_x,
                         ray_hit.hit.Ng_y, ray_hit.hit.Ng_z, ray_hit.hit.u, ray_hit.hit.v);
          }
        }
      } else if (method == CastMethod::kStream) {
        stream.clear();
        stream_cells.clear();
        for (int col0 = 0; col0 < cols; col0 += kTileCols) {
          for (int row = row0; row < row1; ++row) {
            for (int col = col0; col < std::min(cols, col0 + kTileCols); ++col) {
              stream.emplace_back();
              FillRayHit(Ray{origin, direction_at(row, col), t_near, t_far}, &stream.back());
              stream_cells.emplace_back(row, col);
            }
          }
        }
        rtcIntersect1M(scene, &context, stream.data(), static_cast<unsigned>(stream.size()),
                       sizeof(RTCRayHit));
        for (size_t i = 0; i < stream.size(); ++i) {
          const RTCRayHit& h = stream[i];
          writer.Write(stream_cells[i].first, stream_cells[i].second, h.ray.tfar, h.hit.geomID, h.hit.primID,
                       h.hit.Ng_x, h.hit.Ng_y, h.hit.Ng_z, h.hit.u, h.hit.v);
        }
      } else if (method == CastMethod::kPacket8) {
        // 2 x 4 tiles (two rows of a band at a time).
        alignas(32) RTCRayHit8 packet;
        alignas(32) int valid[8];
        for (int sub = row0; sub < row1; sub += 2) {
          for (int col0 = 0; col0 < cols; col0 += 4) {
            for (int i = 0; i < 8; ++i) {
              const int row = sub + i / 4, col = col0 + i % 4;
              const bool inside = row < row1 && col < cols;
              valid[i] = inside ? -1 : 0;
              const Eigen::Vector3f d = inside ? direction_at(row, col) : Eigen::Vector3f::UnitZ();
              packet.ray.org_x[i] = origin.x();
              packet.ray.org_y[i] = origin.y();
              packet.ray.org_z[i] = origin.z();
              packet.ray.dir_x[i] = d.x();
              packet.ray.dir_y[i] = d.y();
              packet.ray.dir_z[i] = d.z();
              packet.ray.tnear[i] = t_near;
              packet.ray.tfar[i] = t_far;
              packet.ray.mask[i] = 0xFFFFFFFFu;
              packet.ray.time[i] = 0.0f;
              packet.ray.flags[i] = 0;
              packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
              packet.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
              packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, scene, &context, &packet);
            for (int i = 0; i < 8; ++i) {
              if (valid[i] == 0) continue;
              writer.Write(sub + i / 4, col0 + i % 4, packet.ray.tfar[i], packet.hit.geomID[i],
                           packet.hit.primID[i], packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i],
                           packet.hit.u[i], packet.hit.v[i]);
            }
          }
        }
      } else {
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[16];
        // Fields Embree does not change are set once per band.
        for (int i = 0; i < 16; ++i) {
          packet.ray.org_x[i] = origin.x();
          packet.ray.org_y[i] = origin.y();
          packet.ray.org_z[i] = origin.z();
          packet.ray.tnear[i] = t_near;
          packet.ray.mask[i] = 0xFFFFFFFFu;
          packet.ray.time[i] = 0.0f;
          packet.ray.flags[i] = 0;
        }
        for (int col0 = 0; col0 < cols; col0 += kTileCols) {
          const bool full = row0 + kTileRows <= row1 && col0 + kTileCols <= cols;
          for (int i = 0; i < 16; ++i) {
            const int row = row0 + i / kTileCols, col = col0 + i % kTileCols;
            const bool inside = full || (row < row1 && col < cols);
            valid[i] = inside ? -1 : 0;
            const Eigen::Vector3f d = inside ? direction_at(row, col) : Eigen::Vector3f::UnitZ();
            packet.ray.dir_x[i] = d.x();
            packet.ray.dir_y[i] = d.y();
            packet.ray.dir_z[i] = d.z();
            packet.ray.tfar[i] = t_far;
            packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
          }
          rtcIntersect16(valid, scene, &context, &packet);
          for (int i = 0; i < 16; ++i) {
            if (valid[i] == 0) continue;
            writer.Write(row0 + i / kTileCols, col0 + i % kTileCols, packet.ray.tfar[i], packet.hit.geomID[i],
                         packet.hit.primID[i], packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i],
                         packet.hit.u[i], packet.hit.v[i]);
          }
        }
      }
    }
  });
}

}  // namespace lidarshop
