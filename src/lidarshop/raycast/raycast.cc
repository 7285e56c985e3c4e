#include "lidarshop/raycast/raycast.h"

#include <embree3/rtcore.h>

#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

struct RaycastScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  bool committed = false;
  // Embree's geometry ids are dense from 0; the user's ids are mapped through this table.
  std::vector<int32_t> user_id_of_geometry;

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

RaycastScene::RaycastScene() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
}

RaycastScene::~RaycastScene() = default;
RaycastScene::RaycastScene(RaycastScene&&) noexcept = default;
RaycastScene& RaycastScene::operator=(RaycastScene&&) noexcept = default;

void RaycastScene::AddMesh(const TriangleMesh& mesh, int32_t id) {
  if (impl_->committed) throw std::logic_error("RaycastScene::AddMesh after Commit");
  if (id < 0) throw std::invalid_argument(fmt::format("RaycastScene::AddMesh: id must be >= 0, got {}", id));
  for (int32_t existing : impl_->user_id_of_geometry) {
    if (existing == id) throw std::invalid_argument(fmt::format("RaycastScene::AddMesh: id {} used twice", id));
  }
  ValidateMesh(mesh, fmt::format("mesh {}", id));
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads vertex buffers 16 bytes at a time: stride 12 with one padding float at the end.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.vertices.size() + 1));
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
  rtcCommitGeometry(geometry);
  const unsigned geometry_id = rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  if (geometry_id != impl_->user_id_of_geometry.size()) throw std::logic_error("Embree geometry ids not dense");
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
  if (hits.size() != rays.size()) throw std::invalid_argument("RaycastScene::Cast: rays and hits differ in size");
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
  if (hits.size() != rays.size()) throw std::invalid_argument("RaycastScene::Cast: rays and hits differ in size");
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
  if (directions.type() != CV_32FC3) throw std::invalid_argument("RaycastScene::CastImage: directions must be CV_32FC3");
  const int rows = directions.rows;
  const int cols = directions.cols;
  RayHitImages images;
  images.t_hit.create(rows, cols, CV_32F);
  images.geometry_id.create(rows, cols, CV_32S);
  images.primitive_id.create(rows, cols, CV_32S);
  images.normal.create(rows, cols, CV_32FC3);
  images.barycentric.create(rows, cols, CV_32FC2);
  ParallelFor(
      rows,
      [&](int64_t row) {
        std::vector<Ray> rays(cols);
        std::vector<RayHit> hits(cols);
        const auto* direction = directions.ptr<cv::Vec3f>(static_cast<int>(row));
        for (int col = 0; col < cols; ++col) {
          rays[col].origin = origin;
          rays[col].direction = Eigen::Vector3f(direction[col][0], direction[col][1], direction[col][2]);
          rays[col].t_near = t_near;
          rays[col].t_far = t_far;
        }
        CastSerial(rays, hits);
        const int r = static_cast<int>(row);
        for (int col = 0; col < cols; ++col) {
          const RayHit& hit = hits[col];
          images.t_hit.at<float>(r, col) = hit.t_hit;
          images.geometry_id.at<int32_t>(r, col) = hit.geometry_id;
          images.primitive_id.at<int32_t>(r, col) = hit.primitive_id;
          images.normal.at<cv::Vec3f>(r, col) = cv::Vec3f(hit.normal.x(), hit.normal.y(), hit.normal.z());
          images.barycentric.at<cv::Vec2f>(r, col) = cv::Vec2f(hit.u, hit.v);
        }
      });
  return images;
}

}  // namespace lidarshop
