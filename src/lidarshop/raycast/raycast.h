// Ray casting against triangle meshes, over Embree 3.
//
// Build once, query many: add meshes (each with an id), Commit(), then cast any number of ray batches from
// any number of threads. A committed scene is immutable and thread-safe to query. Rays are given either as
// flat arrays (hot loops: verification casts a few thousand rays per pose) or as images (a scanner's {rows,
// cols} grid), and hits come back as named arrays/images in the style of Open3D's RaycastingScene: t_hit,
// geometry_id, primitive_id, normal, and barycentric u, v.
//
//   RaycastScene scene;
//   scene.AddMesh(car_in_world, /*id=*/4);
//   scene.Commit();
//   RayHitImages hits = scene.CastImage(scanner_origin, directions);  // directions: CV_32FC3 rows x cols
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

constexpr int32_t kInvalidId = -1;

struct Ray {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f direction = Eigen::Vector3f::UnitY();  // need not be unit; t is in units of |direction|
  float t_near = 0.0f;
  float t_far = std::numeric_limits<float>::infinity();
};

struct RayHit {
  float t_hit = std::numeric_limits<float>::infinity();  // +inf on a miss
  int32_t geometry_id = kInvalidId;                      // the id given to AddMesh, kInvalidId on a miss
  int32_t primitive_id = kInvalidId;                     // triangle index within that mesh
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();      // unit geometric normal (winding side), scene frame
  float u = 0.0f, v = 0.0f;                              // barycentric: hit = (1-u-v)*v0 + u*v1 + v*v2
  bool hit() const { return geometry_id != kInvalidId; }
};

// Hits of an image-shaped ray batch, each rows x cols.
struct RayHitImages {
  cv::Mat t_hit;         // CV_32F, +inf on a miss
  cv::Mat geometry_id;   // CV_32S, kInvalidId on a miss
  cv::Mat primitive_id;  // CV_32S, kInvalidId on a miss
  cv::Mat normal;        // CV_32FC3 unit geometric normal, 0 on a miss
  cv::Mat barycentric;   // CV_32FC2 (u, v)
};

// How CastImage traces an image of rays (all give the same hits; they differ in speed only).
enum class CastMethod {
  kPacket16,  // 4 x 4 tiles of neighbouring cells as rtcIntersect16 packets (coherent; the default, fastest
              // here)
  kPacket8,   // 2 x 4 tiles as rtcIntersect8 packets (the native width of AVX2)
  kStream,    // rows of tiles as rtcIntersect1M streams with the coherent flag
  kSingle,    // one rtcIntersect1 per ray (Open3D's RaycastingScene way; the reference)
};
template <>
const EnumInfo& EnumInfoOf<CastMethod>();

struct RaycastSceneOptions {
  // Embree BVH build quality: "low" builds fastest, "high" (SAH with spatial splits) builds slowest. On the
  // 663k-triangle benchmark scene tracing speed differed by less than the run-to-run noise, while the build
  // took 0.34 / 0.78 / 1.70 s (bench/results/scanner.md), so "medium" is the default.
  std::string build_quality = "medium";
  // RTC_SCENE_FLAG_ROBUST: rays through a shared edge of two triangles do not slip through
  // (without it a ray along a sphere's equator edge missed the front and hit the back;
  // raycast_test). Costs 0-11 % of casting speed.
  bool robust = true;
  bool compact = false;  // RTC_SCENE_FLAG_COMPACT: less memory, slower traversal
  void Check() const;
};
template <>
const StructInfo& InfoOf<RaycastSceneOptions>();

class RaycastScene {
 public:
  RaycastScene();
  explicit RaycastScene(const RaycastSceneOptions& options);
  ~RaycastScene();
  RaycastScene(RaycastScene&&) noexcept;
  RaycastScene& operator=(RaycastScene&&) noexcept;

  // Adds a mesh under `id` (>= 0, unique). Throws before Commit() only. The mesh
  // is copied into Embree's buffers.
  void AddMesh(const TriangleMesh& mesh, int32_t id);
  // Builds the acceleration structure. Casting before Commit() throws.
  void Commit();
  bool committed() const;
  int num_meshes() const;

  // Closest hit of every ray; `hits` must have rays.size() entries. Multithreaded over the batch.
  void Cast(std::span<const Ray> rays, std::span<RayHit> hits) const;
  // Same, single-threaded (for callers that already run in parallel).
  void CastSerial(std::span<const Ray> rays, std::span<RayHit> hits) const;
  // True where the segment origin + t*direction, t in [t_near, t_far], hits anything.
  void Occluded(std::span<const Ray> rays, std::span<uint8_t> occluded) const;

  // One origin, an image of directions (CV_32FC3, need not be unit). Multithreaded.
  RayHitImages CastImage(const Eigen::Vector3f& origin, const cv::Mat& directions, float t_near = 0.0f,
                         float t_far = std::numeric_limits<float>::infinity()) const;
  // A sensor pose: rays start at the origin of `world_from_sensor` with directions_in_sensor (CV_32FC3)
  // rotated into the scene frame; hits (normals included) are in the scene frame. Casting the same scene from
  // many poses needs no rebuild. `method` chooses the Embree API (same hits).
  RayHitImages CastImage(const Eigen::Matrix4d& world_from_sensor, const cv::Mat& directions_in_sensor,
                         float t_near = 0.0f, float t_far = std::numeric_limits<float>::infinity(),
                         CastMethod method = CastMethod::kPacket16) const;
  // Same, writing into `hits` (its images are reused when they already have the right size and type: casting
  // many ray images of one size allocates once).
  void CastImage(const Eigen::Matrix4d& world_from_sensor, const cv::Mat& directions_in_sensor, float t_near,
                 float t_far, CastMethod method, RayHitImages* hits) const;

  // For benchmarks and advanced callers: the RTCScene handle (opaque here to keep Embree out of this header).
  void* native_scene() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lidarshop
