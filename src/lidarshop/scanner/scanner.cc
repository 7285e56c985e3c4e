#include "lidarshop/scanner/scanner.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <vector>

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
  // Per triangle: 1 where the vertex normals differ from the face normal (curved surfaces); empty when no
  // triangle is curved (the geometric normal is then exact and no vertex normal is read).
  std::vector<uint8_t> smooth;
};

// 65,536 standard-normal quantiles Φ^-1((i + 0.5) / 65536): Acklam's rational approximation refined by one
// Halley step with erfc (accurate to ~1e-15).
const std::vector<float>& NormalQuantiles() {
  static const std::vector<float> table = [] {
    constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                            1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
    constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                            6.680131188771972e+01, -1.328068155288572e+01};
    constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                            -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
    constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                            3.754408661907416e+00};
    std::vector<float> quantiles(4097);
    for (int i = 0; i <= 4096; ++i) {
      const double p = std::clamp(i / 4096.0, 0.5 / 65536.0, 1.0 - 0.5 / 65536.0);
      double x;
      if (p < 0.02425) {
        const double q = std::sqrt(-2 * std::log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
      } else if (p <= 1 - 0.02425) {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
      } else {
        const double q = std::sqrt(-2 * std::log(1 - p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
      }
      const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
      const double u = e * std::sqrt(2 * M_PI) * std::exp(x * x / 2);
      x = x - u / (1 + x * u / 2);
      quantiles[i] = static_cast<float>(x);
    }
    return quantiles;
  }();
  return table;
}

// A standard normal from 16 uniform bits (inverse-CDF sampling through the quantile table).
inline float NormalFrom16Bits(const float* quantiles, uint32_t bits) {
  const uint32_t index = bits >> 4;
  const float fraction = static_cast<float>(bits & 15u) * (1.0f / 16.0f) + (1.0f / 32.0f);
  return quantiles[index] + fraction * (quantiles[index + 1] - quantiles[index]);
}

// cos and sin of (i + 0.5) * 2π / 1024.
const std::vector<Eigen::Vector2f>& UnitCircle() {
  static const std::vector<Eigen::Vector2f> table = [] {
    std::vector<Eigen::Vector2f> circle(1024);
    for (int i = 0; i < 1024; ++i) {
      const double angle = (i + 0.5) * 2 * M_PI / 1024;
      circle[i] = Eigen::Vector2f(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)));
    }
    return circle;
  }();
  return table;
}

inline float Luminance(Rgb8 color) {
  return (0.299f * color[0] + 0.587f * color[1] + 0.114f * color[2]) / 255.0f;
}

}  // namespace

struct SyntheticScanner::Impl {
  explicit Impl(const RaycastSceneOptions& options) : raycast(options) {}
  RaycastScene raycast;
  std::vector<ObjectData> objects;
  int64_t num_triangles = 0;
  double build_seconds = 0.0;
};

double CellUniform(uint64_t seed, uint64_t cell, uint32_t stream) {
  return Uniform(seed, cell, 1000 + stream);
}
double CellNormal(uint64_t seed, uint64_t cell, uint32_t stream) { return Normal(seed, cell, 1000 + stream); }

SyntheticScanner::SyntheticScanner(const SceneDescription& scene, const RaycastSceneOptions& raycast_options)
    : impl_(std::make_unique<Impl>(raycast_options)) {
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
    const TriangleMesh& mesh = data.mesh_in_world;
    if (!mesh.vertex_normals.empty()) {
      data.smooth.resize(mesh.triangles.size(), 0);
      bool any = false;
      for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        const Eigen::Vector3i& t = mesh.triangles[f];
        const Eigen::Vector3f face = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                         .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                         .normalized();
        for (int corner = 0; corner < 3; ++corner) {
          if (mesh.vertex_normals[t[corner]].dot(face) < 1.0f - 1e-6f) data.smooth[f] = 1;
        }
        any = any || data.smooth[f];
      }
      if (!any) data.smooth.clear();
    }
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
  Scan scan;
  AcquireInto(options, &scan, progress, stats);
  return scan;
}

namespace {

// Output channels of one image row (raw pointers: the hot loop writes them directly).
struct RowOut {
  cv::Vec3f* direction;
  uint8_t* valid;
  float* range;
  cv::Vec3f* point;
  float* intensity;
  cv::Vec3b* color;
  int32_t* label;
  cv::Vec3f* normal;
  float* true_range;

  RowOut(Scan& scan, int row)
      : direction(scan.direction.ptr<cv::Vec3f>(row)),
        valid(scan.valid.ptr<uint8_t>(row)),
        range(scan.range.ptr<float>(row)),
        point(scan.point.ptr<cv::Vec3f>(row)),
        intensity(scan.intensity.ptr<float>(row)),
        color(scan.color.ptr<cv::Vec3b>(row)),
        label(scan.label.ptr<int32_t>(row)),
        normal(scan.normal.ptr<cv::Vec3f>(row)),
        true_range(scan.true_range.ptr<float>(row)) {}
  RowOut() = default;
};

// Per-thread staging rows for one 4-row band: the fused loop shades into these (in L2, written in tile
// order), then each channel row is copied out contiguously (a few long sequential streams instead of 36
// interleaved ones, which stalled the store buffer on read-for-ownership misses).
struct BandStaging {
  int cols = 0;
  std::vector<uint8_t> valid;
  std::vector<float> range, intensity, true_range;
  std::vector<cv::Vec3f> point, normal;
  std::vector<cv::Vec3b> color;
  std::vector<int32_t> label;

  void Resize(int new_cols) {
    if (cols == new_cols) return;
    cols = new_cols;
    const size_t n = static_cast<size_t>(4) * cols;
    valid.resize(n);
    range.resize(n);
    intensity.resize(n);
    true_range.resize(n);
    point.resize(n);
    normal.resize(n);
    color.resize(n);
    label.resize(n);
  }
  // Row r of the band; `direction` is the scan's own (already filled) direction row.
  RowOut Row(int r, cv::Vec3f* direction) {
    RowOut out;
    const size_t o = static_cast<size_t>(r) * cols;
    out.direction = direction;
    out.valid = valid.data() + o;
    out.range = range.data() + o;
    out.point = point.data() + o;
    out.intensity = intensity.data() + o;
    out.color = color.data() + o;
    out.label = label.data() + o;
    out.normal = normal.data() + o;
    out.true_range = true_range.data() + o;
    return out;
  }
  void CopyOut(int r, const RowOut& to) const {
    const size_t o = static_cast<size_t>(r) * cols;
    std::memcpy(to.valid, valid.data() + o, cols * sizeof(uint8_t));
    std::memcpy(to.range, range.data() + o, cols * sizeof(float));
    std::memcpy(to.point, point.data() + o, cols * sizeof(cv::Vec3f));
    std::memcpy(to.intensity, intensity.data() + o, cols * sizeof(float));
    std::memcpy(to.color, color.data() + o, cols * sizeof(cv::Vec3b));
    std::memcpy(to.label, label.data() + o, cols * sizeof(int32_t));
    std::memcpy(to.normal, normal.data() + o, cols * sizeof(cv::Vec3f));
    std::memcpy(to.true_range, true_range.data() + o, cols * sizeof(float));
  }
};

// Everything the per-hit shading reads, set up once per scan; Hit() and Miss() fill one cell.
struct Shader {
  const ObjectData* objects = nullptr;
  Eigen::Matrix3f world_from_scanner_rotation;
  Eigen::Matrix3f scanner_from_world_rotation;
  Eigen::Vector3f origin;
  float los_sigma = 0, orthogonal_sigma = 0;
  bool noisy = false;
  uint64_t seed_key = 0;
  int cols = 0;
  const float* quantiles = nullptr;
  const Eigen::Vector2f* circle = nullptr;
  const float* falloff = nullptr;  // exp(-t / falloff_m) at t = i * max_range / kFalloffSteps
  float inverse_falloff_step = 0;
  float angular_step_rad = 0;          // the larger of the azimuth and elevation steps (texture footprint)
  const float* sin_azimuth = nullptr;  // per column
  const float* cos_azimuth = nullptr;
  static constexpr int kFalloffSteps = 1024;

  static inline void Miss(const RowOut& out, int col) {
    out.valid[col] = 0;
    out.range[col] = 0.0f;
    out.point[col] = cv::Vec3f(0, 0, 0);
    out.intensity[col] = 0.5f;
    out.color[col] = cv::Vec3b(0, 0, 0);
    out.label[col] = kNoLabel;
    out.normal[col] = cv::Vec3f(0, 0, 0);
    out.true_range[col] = 0.0f;
  }

  // One return: t along the unit scanner-frame direction d_scanner (d_world in the world frame), object `id`,
  // `triangle`, barycentric (u, v), geometric normal (any length) in the world frame.
  inline __attribute__((always_inline)) void Hit(const RowOut& out, int row, int col, float t, int32_t id,
                                                 int32_t triangle, float u, float v,
                                                 const Eigen::Vector3f& geometric_normal,
                                                 const Eigen::Vector3f& d_scanner,
                                                 const Eigen::Vector3f& d_world) const {
    const ObjectData& object = objects[id];
    const TriangleMesh& mesh = object.mesh_in_world;
    const float w = 1.0f - u - v;
    Eigen::Vector3f n_world = geometric_normal * (1.0f / std::sqrt(geometric_normal.squaredNorm()));
    if (!object.smooth.empty() && object.smooth[triangle]) {
      const Eigen::Vector3i& corners = mesh.triangles[triangle];
      const Eigen::Vector3f smooth = w * mesh.vertex_normals[corners[0]] +
                                     u * mesh.vertex_normals[corners[1]] +
                                     v * mesh.vertex_normals[corners[2]];
      const float norm = smooth.norm();
      if (norm > 1e-6f) n_world = smooth / norm;
    }
    float n_dot_d = n_world.dot(d_world);
    if (n_dot_d > 0) {  // facing the scanner
      n_world = -n_world;
      n_dot_d = -n_dot_d;
    }
    const float cos_incidence = std::min(-n_dot_d, 1.0f);

    Rgb8 surface;
    if (!mesh.triangle_colors.empty()) {
      surface = mesh.triangle_colors[triangle];
    } else if (!mesh.vertex_colors.empty()) {
      const Eigen::Vector3i& corners = mesh.triangles[triangle];
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
      const Eigen::Vector2f uv = TriplanarCoordinates(p_object, object.texture_from_world_rotation * n_world);
      // The ray's footprint on the surface (band-limits the texture: no moiré at range).
      const float footprint_m = t * angular_step_rad / std::max(cos_incidence, 0.02f);
      surface = EvaluateTexture(object.material.texture, uv.x(), uv.y(), surface,
                                object.material.texture_scale, footprint_m);
    } else if (object.has_texture_image) {
      const Eigen::Vector3i& tc = mesh.triangle_texcoords[triangle];
      const Eigen::Vector2f st =
          w * mesh.texcoords[tc[0]] + u * mesh.texcoords[tc[1]] + v * mesh.texcoords[tc[2]];
      surface = SampleImageTexture(mesh.texture, st.x(), st.y());
    }
    const float reflectivity = object.material.reflectivity * (0.5f + Luminance(surface));
    const float f = std::clamp(t * inverse_falloff_step, 0.0f, static_cast<float>(kFalloffSteps));
    const int fi = static_cast<int>(f);
    const float attenuation = falloff[fi] + (f - fi) * (falloff[fi + 1] - falloff[fi]);
    out.intensity[col] = std::clamp(reflectivity * std::max(cos_incidence, 0.0f) * attenuation, 0.0f, 1.0f);

    Eigen::Vector3f p = t * d_scanner;
    float range = t;
    if (noisy) {
      // One 64-bit hash per cell: 16 bits for e_los, 16 for e_orth, 10 for ψ.
      const uint64_t bits = SplitMix64(seed_key ^ (static_cast<uint64_t>(row) * cols + col));
      const float e_los = los_sigma * NormalFrom16Bits(quantiles, bits & 0xFFFFu);
      p += e_los * d_scanner;
      if (orthogonal_sigma > 0) {
        // b1 = (cos θ, -sin θ, 0) (horizontal, ⟂ d for every elevation), b2 = d × b1.
        const float ca = cos_azimuth[col], sa = sin_azimuth[col];
        const Eigen::Vector3f b1(ca, -sa, 0.0f);
        const Eigen::Vector3f b2(d_scanner.z() * sa, d_scanner.z() * ca,
                                 -(d_scanner.x() * sa + d_scanner.y() * ca));
        const Eigen::Vector2f& psi = circle[(bits >> 32) & 0x3FFu];
        const float e_orth = orthogonal_sigma * NormalFrom16Bits(quantiles, (bits >> 16) & 0xFFFFu);
        p += (e_orth * psi.x()) * b1 + (e_orth * psi.y()) * b2;
      }
      range = p.norm();
    }
    const Eigen::Vector3f n_scanner = scanner_from_world_rotation * n_world;
    out.valid[col] = kValid;
    out.true_range[col] = t;
    out.range[col] = range;
    out.point[col] = cv::Vec3f(p.x(), p.y(), p.z());
    out.color[col] = cv::Vec3b(surface[0], surface[1], surface[2]);
    out.label[col] = object.label;
    out.normal[col] = cv::Vec3f(n_scanner.x(), n_scanner.y(), n_scanner.z());
  }
};

}  // namespace

void SyntheticScanner::AcquireInto(const ScannerOptions& options, Scan* scan_out, Progress* progress,
                                   ScanStats* stats) const {
  options.Check();
  const int rows = options.rows, cols = options.columns;
  // Every channel is written for every cell by the loops below, so nothing is pre-filled.
  Scan& scan = *scan_out;
  scan.synthesized.release();
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

  // Directions exactly as DirectionsFromGrid (double products, then float), from per-row and per-column
  // sines.
  std::vector<double> sin_azimuth(cols), cos_azimuth(cols), sin_elevation(rows), cos_elevation(rows);
  std::vector<float> sin_azimuth_f(cols), cos_azimuth_f(cols);
  for (int col = 0; col < cols; ++col) {
    sin_azimuth[col] = std::sin(scan.grid.azimuth_rad[col]);
    cos_azimuth[col] = std::cos(scan.grid.azimuth_rad[col]);
    sin_azimuth_f[col] = static_cast<float>(sin_azimuth[col]);
    cos_azimuth_f[col] = static_cast<float>(cos_azimuth[col]);
  }
  for (int row = 0; row < rows; ++row) {
    sin_elevation[row] = std::sin(scan.grid.elevation_rad[row]);
    cos_elevation[row] = std::cos(scan.grid.elevation_rad[row]);
  }
  auto fill_directions = [&](int row) {
    auto* direction = scan.direction.ptr<cv::Vec3f>(row);
    for (int col = 0; col < cols; ++col) {
      direction[col] = cv::Vec3f(static_cast<float>(cos_elevation[row] * sin_azimuth[col]),
                                 static_cast<float>(cos_elevation[row] * cos_azimuth[col]),
                                 static_cast<float>(sin_elevation[row]));
    }
  };

  // exp(-t / falloff) tabulated over [0, max range] (linear interpolation, relative error < 1e-6).
  constexpr int kFalloffSteps = Shader::kFalloffSteps;
  std::vector<float> falloff(kFalloffSteps + 2);
  for (int i = 0; i < kFalloffSteps + 2; ++i) {
    falloff[i] =
        static_cast<float>(std::exp(-i * options.max_range_m / kFalloffSteps / options.intensity_falloff_m));
  }
  Shader shader;
  shader.objects = impl_->objects.data();
  shader.world_from_scanner_rotation = scan.world_from_scanner.topLeftCorner<3, 3>().cast<float>();
  shader.scanner_from_world_rotation = shader.world_from_scanner_rotation.transpose();
  shader.origin = options.position.cast<float>();
  shader.los_sigma = static_cast<float>(options.los_noise_sigma_m);
  shader.orthogonal_sigma = static_cast<float>(options.orthogonal_noise_sigma_m);
  shader.noisy = shader.los_sigma > 0 || shader.orthogonal_sigma > 0;
  shader.seed_key = SplitMix64(options.seed ^ 0x5851F42D4C957F2Dull);
  shader.cols = cols;
  shader.quantiles = NormalQuantiles().data();
  shader.circle = UnitCircle().data();
  shader.falloff = falloff.data();
  shader.inverse_falloff_step = static_cast<float>(kFalloffSteps / options.max_range_m);
  const double azimuth_step = cols > 1 ? std::abs(scan.grid.azimuth_rad[1] - scan.grid.azimuth_rad[0]) : 0.0;
  const double elevation_step =
      rows > 1 ? std::abs(scan.grid.elevation_rad[1] - scan.grid.elevation_rad[0]) : 0.0;
  shader.angular_step_rad =
      options.filter_textures ? static_cast<float>(std::max(azimuth_step, elevation_step)) : 0.0f;
  shader.sin_azimuth = sin_azimuth_f.data();
  shader.cos_azimuth = cos_azimuth_f.data();
  const Eigen::Matrix3f& rotation = shader.world_from_scanner_rotation;
  const float t_near = static_cast<float>(options.min_range_m);
  const float t_far = static_cast<float>(options.max_range_m);

  ScanStats local_stats;
  local_stats.rays = scan.num_cells();
  std::atomic<int64_t> returns{0};
  Timer timer;
  // Rows are cast and shaded in chunks (a multiple of the 4-row tile bands), so that progress moves.
  const int chunk_rows = (std::clamp(rows / 16, 16, 128) + 3) / 4 * 4;

  if (options.cast_method == CastMethod::kPacket16 || options.cast_method == CastMethod::kStream) {
    // Fused: each band of 4 rows is cast as 4 x 4 tiles (rtcIntersect16 packets, or one rtcIntersect1M stream
    // per band in tile order), and every hit is shaded right after into the thread's staging rows (no hit
    // images); the band's rows are then copied out channel by channel.
    RTCScene rtc_scene = static_cast<RTCScene>(impl_->raycast.native_scene());
    const bool use_stream = options.cast_method == CastMethod::kStream;
    for (int chunk_begin = 0; chunk_begin < rows; chunk_begin += chunk_rows) {
      const int chunk_end = std::min(rows, chunk_begin + chunk_rows);
      const int bands = (chunk_end - chunk_begin + 3) / 4;
      ParallelForRange(bands, [&](int64_t band_begin, int64_t band_end) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) RTCRayHit16 packet;
        alignas(64) int lane_valid[16];
        for (int i = 0; i < 16; ++i) {
          packet.ray.org_x[i] = shader.origin.x();
          packet.ray.org_y[i] = shader.origin.y();
          packet.ray.org_z[i] = shader.origin.z();
          packet.ray.tnear[i] = t_near;
          packet.ray.mask[i] = 0xFFFFFFFFu;
          packet.ray.time[i] = 0.0f;
          packet.ray.flags[i] = 0;
        }
        thread_local BandStaging staging;
        staging.Resize(cols);
        std::vector<RTCRayHit> stream;
        std::vector<int32_t> stream_cells;  // (row in band << 24) | col
        int64_t band_returns = 0;
        for (int64_t band = band_begin; band < band_end; ++band) {
          const int row0 = chunk_begin + static_cast<int>(band) * 4;
          const int row1 = std::min(chunk_end, row0 + 4);
          for (int row = row0; row < row1; ++row) fill_directions(row);
          RowOut outs[4];
          for (int r = 0; r < 4; ++r) {
            outs[r] = staging.Row(r, scan.direction.ptr<cv::Vec3f>(std::min(row0 + r, row1 - 1)));
          }
          auto shade = [&](int r, int col, unsigned geometry, unsigned primitive, float t, float u, float v,
                           float nx, float ny, float nz, float dx, float dy, float dz)
              __attribute__((always_inline)) {
            const RowOut& out = outs[r];
            if (geometry == RTC_INVALID_GEOMETRY_ID) {
              Shader::Miss(out, col);
              return;
            }
            ++band_returns;
            const cv::Vec3f& d = out.direction[col];
            shader.Hit(out, row0 + r, col, t, static_cast<int32_t>(geometry), static_cast<int32_t>(primitive),
                       u, v, Eigen::Vector3f(nx, ny, nz), Eigen::Vector3f(d[0], d[1], d[2]),
                       Eigen::Vector3f(dx, dy, dz));
          };
          if (use_stream) {
            stream.clear();
            stream_cells.clear();
            for (int col0 = 0; col0 < cols; col0 += 4) {
              for (int row = row0; row < row1; ++row) {
                for (int col = col0; col < std::min(cols, col0 + 4); ++col) {
                  const cv::Vec3f d = outs[row - row0].direction[col];
                  RTCRayHit& ray_hit = stream.emplace_back();
                  ray_hit.ray.org_x = shader.origin.x();
                  ray_hit.ray.org_y = shader.origin.y();
                  ray_hit.ray.org_z = shader.origin.z();
                  ray_hit.ray.dir_x = rotation(0, 0) * d[0] + rotation(0, 1) * d[1] + rotation(0, 2) * d[2];
                  ray_hit.ray.dir_y = rotation(1, 0) * d[0] + rotation(1, 1) * d[1] + rotation(1, 2) * d[2];
                  ray_hit.ray.dir_z = rotation(2, 0) * d[0] + rotation(2, 1) * d[1] + rotation(2, 2) * d[2];
                  ray_hit.ray.tnear = t_near;
                  ray_hit.ray.tfar = t_far;
                  ray_hit.ray.mask = 0xFFFFFFFFu;
                  ray_hit.ray.flags = 0;
                  ray_hit.ray.time = 0.0f;
                  ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                  ray_hit.hit.primID = RTC_INVALID_GEOMETRY_ID;
                  ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                  stream_cells.push_back(((row - row0) << 24) | col);
                }
              }
            }
            rtcIntersect1M(rtc_scene, &context, stream.data(), static_cast<unsigned>(stream.size()),
                           sizeof(RTCRayHit));
            for (size_t i = 0; i < stream.size(); ++i) {
              const RTCRayHit& h = stream[i];
              shade(stream_cells[i] >> 24, stream_cells[i] & 0xFFFFFF, h.hit.geomID, h.hit.primID, h.ray.tfar,
                    h.hit.u, h.hit.v, h.hit.Ng_x, h.hit.Ng_y, h.hit.Ng_z, h.ray.dir_x, h.ray.dir_y,
                    h.ray.dir_z);
            }
            for (int row = row0; row < row1; ++row) staging.CopyOut(row - row0, RowOut(scan, row));
            continue;
          }
          for (int col0 = 0; col0 < cols; col0 += 4) {
            const bool full = row1 - row0 == 4 && col0 + 4 <= cols;
            for (int i = 0; i < 16; ++i) {
              const int r = i >> 2, col = col0 + (i & 3);
              const bool inside = full || (row0 + r < row1 && col < cols);
              lane_valid[i] = inside ? -1 : 0;
              const cv::Vec3f d = inside ? outs[r].direction[col] : cv::Vec3f(0, 0, 1);
              packet.ray.dir_x[i] = rotation(0, 0) * d[0] + rotation(0, 1) * d[1] + rotation(0, 2) * d[2];
              packet.ray.dir_y[i] = rotation(1, 0) * d[0] + rotation(1, 1) * d[1] + rotation(1, 2) * d[2];
              packet.ray.dir_z[i] = rotation(2, 0) * d[0] + rotation(2, 1) * d[1] + rotation(2, 2) * d[2];
              packet.ray.tfar[i] = t_far;
              packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
              packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(lane_valid, rtc_scene, &context, &packet);
            for (int i = 0; i < 16; ++i) {
              if (lane_valid[i] == 0) continue;
              shade(i >> 2, col0 + (i & 3), packet.hit.geomID[i], packet.hit.primID[i], packet.ray.tfar[i],
                    packet.hit.u[i], packet.hit.v[i], packet.hit.Ng_x[i], packet.hit.Ng_y[i],
                    packet.hit.Ng_z[i], packet.ray.dir_x[i], packet.ray.dir_y[i], packet.ray.dir_z[i]);
            }
          }
          for (int row = row0; row < row1; ++row) staging.CopyOut(row - row0, RowOut(scan, row));
        }
        returns += band_returns;
      });
      Advance(progress, chunk_end - chunk_begin);
    }
    local_stats.cast_seconds = timer.Seconds();  // casting and shading, fused
  } else {
    // Other cast methods: cast a chunk into hit images, then shade them.
    RayHitImages hits;
    for (int chunk_begin = 0; chunk_begin < rows; chunk_begin += chunk_rows) {
      const int chunk_end = std::min(rows, chunk_begin + chunk_rows);
      timer.Restart();
      ParallelFor(chunk_end - chunk_begin,
                  [&](int64_t chunk_row) { fill_directions(chunk_begin + chunk_row); });
      impl_->raycast.CastImage(scan.world_from_scanner, scan.direction.rowRange(chunk_begin, chunk_end),
                               t_near, t_far, options.cast_method, &hits);
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
            const RowOut out(scan, row);
            int64_t row_returns = 0;
            for (int col = 0; col < cols; ++col) {
              const int32_t id = geometry_id[col];
              if (id < 0) {
                Shader::Miss(out, col);
                continue;
              }
              ++row_returns;
              const Eigen::Vector3f d_scanner(out.direction[col][0], out.direction[col][1],
                                              out.direction[col][2]);
              const cv::Vec3f& n = geometric_normal[col];
              shader.Hit(out, row, col, t_hit[col], id, primitive_id[col], barycentric[col][0],
                         barycentric[col][1], Eigen::Vector3f(n[0], n[1], n[2]), d_scanner,
                         rotation * d_scanner);
            }
            returns += row_returns;
          },
          4);
      local_stats.shade_seconds += timer.Seconds();
      Advance(progress, chunk_end - chunk_begin);
    }
  }
  local_stats.returns = returns.load();
  if (stats != nullptr) *stats = local_stats;
}

Scan SynthesizeScan(const SceneDescription& scene, Progress* progress) {
  const SyntheticScanner scanner(scene);
  return scanner.Acquire(scene.scanner, progress);
}

}  // namespace lidarshop
