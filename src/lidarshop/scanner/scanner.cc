#include "lidarshop/scanner/scanner.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/SVD>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {
namespace {

inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform in (0, 1), 53 bits.
inline double Uniform(uint64_t seed, uint64_t cell, uint32_t stream) {
  const uint64_t key = SplitMix64(SplitMix64(seed ^ 0x5851F42D4C957F2Dull) ^ cell) ^ (uint64_t{stream} << 56);
  return (static_cast<double>(SplitMix64(key) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

inline double Normal(uint64_t seed, uint64_t cell, uint32_t stream) {
  // Box-Muller with two independent uniforms of the same (seed, cell).
  const double u1 = Uniform(seed, cell, 2 * stream);
  const double u2 = Uniform(seed, cell, 2 * stream + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Per-object data the shading loop reads.
struct ObjectData {
  TriangleMesh mesh_in_world;  // vertex normals in the world frame
  Eigen::Matrix3f texture_from_world_rotation;
  Eigen::Vector3f world_origin_of_object;
  Material material;
  int32_t label = 0;
  bool has_texture_image = false;
};

inline float Luminance(Rgb8 color) {
  return (0.299f * color[0] + 0.587f * color[1] + 0.114f * color[2]) / 255.0f;
}

}  // namespace

struct SyntheticScanner::Impl {
  RaycastScene raycast;
  std::vector<ObjectData> objects;
  int64_t num_triangles = 0;
  double build_seconds = 0.0;
};

double CellUniform(uint64_t seed, uint64_t cell, uint32_t stream) {
  return Uniform(seed, cell, 1000 + stream);
}
double CellNormal(uint64_t seed, uint64_t cell, uint32_t stream) { return Normal(seed, cell, 1000 + stream); }

SyntheticScanner::SyntheticScanner(const SceneDescription& scene) : impl_(std::make_unique<Impl>()) {
  Timer timer;
  impl_->objects.resize(scene.objects.size());
  ParallelFor(static_cast<int64_t>(scene.objects.size()), [&](int64_t i) {
    const SceneObject& object = scene.objects[i];
    ObjectData& data = impl_->objects[i];
    data.mesh_in_world = MeshInWorld(object);
    const Eigen::Matrix3d linear = object.world_from_object.topLeftCorner<3, 3>();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();  // the scale-free part
    data.texture_from_world_rotation = rotation.transpose().cast<float>();
    data.world_origin_of_object = object.world_from_object.topRightCorner<3, 1>().cast<float>();
    data.material = object.material;
    data.label = object.label;
    data.has_texture_image = !object.mesh.texture.empty() && !object.mesh.triangle_texcoords.empty();
  });
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
  options.Check();
  const int rows = options.rows, cols = options.columns;
  Scan scan = MakeScan(rows, cols, /*with_color=*/true);
  scan.name = "synthetic";
  scan.grid = options.Grid();
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.world_from_scanner = options.WorldFromScanner();
  scan.label = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNoLabel));
  scan.normal = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
  scan.true_range = cv::Mat(rows, cols, CV_32F, cv::Scalar(0));

  const Eigen::Matrix3f world_from_scanner_rotation =
      scan.world_from_scanner.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Matrix3f scanner_from_world_rotation = world_from_scanner_rotation.transpose();
  const Eigen::Vector3f origin = options.position.cast<float>();
  const float los_sigma = static_cast<float>(options.los_noise_sigma_m);
  const float orthogonal_sigma = static_cast<float>(options.orthogonal_noise_sigma_m);
  const float inverse_falloff = static_cast<float>(1.0 / options.intensity_falloff_m);
  const bool noisy = los_sigma > 0 || orthogonal_sigma > 0;
  const std::vector<ObjectData>& objects = impl_->objects;

  // Rows are cast and shaded in chunks, so that progress moves and the hit images of a chunk stay in cache.
  const int chunk_rows = std::clamp(rows / 16, 16, 128);
  ScanStats local_stats;
  local_stats.rays = scan.num_cells();
  Timer timer;
  for (int chunk_begin = 0; chunk_begin < rows; chunk_begin += chunk_rows) {
    const int chunk_end = std::min(rows, chunk_begin + chunk_rows);
    timer.Restart();
    const RayHitImages hits = impl_->raycast.CastImage(
        scan.world_from_scanner, scan.direction.rowRange(chunk_begin, chunk_end),
        static_cast<float>(options.min_range_m), static_cast<float>(options.max_range_m));
    local_stats.cast_seconds += timer.Seconds();
    timer.Restart();
    ParallelFor(
        chunk_end - chunk_begin,
        [&](int64_t chunk_row) {
          const int row = chunk_begin + static_cast<int>(chunk_row);
          const int hit_row = static_cast<int>(chunk_row);
          const auto* t_hit = hits.t_hit.ptr<float>(hit_row);
          const auto* geometry_id = hits.geometry_id.ptr<int32_t>(hit_row);
          const auto* primitive_id = hits.primitive_id.ptr<int32_t>(hit_row);
          const auto* geometric_normal = hits.normal.ptr<cv::Vec3f>(hit_row);
          const auto* barycentric = hits.barycentric.ptr<cv::Vec2f>(hit_row);
          const auto* direction = scan.direction.ptr<cv::Vec3f>(row);
          auto* valid = scan.valid.ptr<uint8_t>(row);
          auto* range = scan.range.ptr<float>(row);
          auto* point = scan.point.ptr<cv::Vec3f>(row);
          auto* intensity = scan.intensity.ptr<float>(row);
          auto* color = scan.color.ptr<cv::Vec3b>(row);
          auto* label = scan.label.ptr<int32_t>(row);
          auto* normal = scan.normal.ptr<cv::Vec3f>(row);
          auto* true_range = scan.true_range.ptr<float>(row);
          for (int col = 0; col < cols; ++col) {
            const int32_t id = geometry_id[col];
            if (id < 0) continue;
            const ObjectData& object = objects[id];
            const TriangleMesh& mesh = object.mesh_in_world;
            const int32_t triangle = primitive_id[col];
            const float t = t_hit[col];
            const float u = barycentric[col][0], v = barycentric[col][1], w = 1.0f - u - v;
            const Eigen::Vector3f d_scanner(direction[col][0], direction[col][1], direction[col][2]);
            const Eigen::Vector3f d_world = world_from_scanner_rotation * d_scanner;
            const Eigen::Vector3i& corners = mesh.triangles[triangle];
            Eigen::Vector3f n_world(geometric_normal[col][0], geometric_normal[col][1],
                                    geometric_normal[col][2]);
            if (!mesh.vertex_normals.empty()) {
              const Eigen::Vector3f smooth = w * mesh.vertex_normals[corners[0]] +
                                             u * mesh.vertex_normals[corners[1]] +
                                             v * mesh.vertex_normals[corners[2]];
              const float norm = smooth.norm();
              if (norm > 1e-6f) n_world = smooth / norm;
            }
            if (n_world.dot(d_world) > 0) n_world = -n_world;  // facing the scanner
            const float cos_incidence = std::clamp(-n_world.dot(d_world), 0.0f, 1.0f);

            Rgb8 surface;
            if (!mesh.triangle_colors.empty()) {
              surface = mesh.triangle_colors[triangle];
            } else if (!mesh.vertex_colors.empty()) {
              const Eigen::Vector3f mixed = w * mesh.vertex_colors[corners[0]].cast<float>() +
                                            u * mesh.vertex_colors[corners[1]].cast<float>() +
                                            v * mesh.vertex_colors[corners[2]].cast<float>();
              surface = (mixed.array() + 0.5f).cast<uint8_t>();
            } else {
              surface = object.material.color;
            }
            if (object.material.texture != TextureKind::kNone) {
              const Eigen::Vector3f p_world = origin + t * d_world;
              const Eigen::Vector3f p_object =
                  object.texture_from_world_rotation * (p_world - object.world_origin_of_object);
              const Eigen::Vector2f uv =
                  TriplanarCoordinates(p_object, object.texture_from_world_rotation * n_world);
              surface = EvaluateTexture(object.material.texture, uv.x(), uv.y(), surface,
                                        object.material.texture_scale);
            } else if (object.has_texture_image) {
              const Eigen::Vector3i& tc = mesh.triangle_texcoords[triangle];
              const Eigen::Vector2f st =
                  w * mesh.texcoords[tc[0]] + u * mesh.texcoords[tc[1]] + v * mesh.texcoords[tc[2]];
              surface = SampleImageTexture(mesh.texture, st.x(), st.y());
            }
            const float reflectivity = object.material.reflectivity * (0.5f + Luminance(surface));
            intensity[col] =
                std::clamp(reflectivity * cos_incidence * std::exp(-t * inverse_falloff), 0.0f, 1.0f);

            Eigen::Vector3f p = t * d_scanner;
            if (noisy) {
              const uint64_t cell = static_cast<uint64_t>(row) * cols + col;
              const float e_los =
                  los_sigma > 0 ? los_sigma * static_cast<float>(Normal(options.seed, cell, 0)) : 0.0f;
              p += e_los * d_scanner;
              if (orthogonal_sigma > 0) {
                const float e_orthogonal =
                    orthogonal_sigma * static_cast<float>(Normal(options.seed, cell, 1));
                const float psi = static_cast<float>(2.0 * M_PI * Uniform(options.seed, cell, 4));
                Eigen::Vector3f b1 = d_scanner.cross(Eigen::Vector3f::UnitZ());
                if (b1.squaredNorm() < 1e-8f) b1 = d_scanner.cross(Eigen::Vector3f::UnitX());
                b1.normalize();
                const Eigen::Vector3f b2 = d_scanner.cross(b1);
                p += e_orthogonal * (std::cos(psi) * b1 + std::sin(psi) * b2);
              }
            }
            const Eigen::Vector3f n_scanner = scanner_from_world_rotation * n_world;
            valid[col] = kValid;
            true_range[col] = t;
            range[col] = noisy ? p.norm() : t;
            point[col] = cv::Vec3f(p.x(), p.y(), p.z());
            color[col] = cv::Vec3b(surface[0], surface[1], surface[2]);
            label[col] = object.label;
            normal[col] = cv::Vec3f(n_scanner.x(), n_scanner.y(), n_scanner.z());
          }
        },
        4);
    local_stats.shade_seconds += timer.Seconds();
    Advance(progress, chunk_end - chunk_begin);
  }
  local_stats.returns = scan.CountValid();
  if (stats != nullptr) *stats = local_stats;
  return scan;
}

Scan SynthesizeScan(const SceneDescription& scene, Progress* progress) {
  const SyntheticScanner scanner(scene);
  return scanner.Acquire(scene.scanner, progress);
}

}  // namespace lidarshop
