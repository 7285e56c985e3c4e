#include "lidarshop/scanner/shade.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Eigen/SVD>

#include "lidarshop/scanner/texture_lanes.h"

namespace lidarshop::scanner_internal {
namespace {

using lanes::F8;
using lanes::I8;
using lanes::kWidth;
using lanes::Splat;
using lanes::ToFloat;
using lanes::ToInt;
using lanes::U8;

// The 65,536 standard-normal quantiles Φ^-1((i + 0.5) / 65536), one per value of 16 uniform bits: Acklam's
// rational approximation refined by one Halley step with erfc (accurate to ~1e-15). 256 KB, read by one
// gather per normal (a 4,097-entry table with interpolation needs two).
std::vector<float> NormalQuantiles() {
  constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                          1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                          6.680131188771972e+01, -1.328068155288572e+01};
  constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                          -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                          3.754408661907416e+00};
  std::vector<float> quantiles(65536);
  for (int i = 0; i < 65536; ++i) {
    const double p = (i + 0.5) / 65536.0;
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
}

struct NoiseTables {
  std::vector<float> quantiles = NormalQuantiles();
  // cos and sin of (i + 0.5) * 2π / 1024.
  std::vector<float> circle_cos = std::vector<float>(1024), circle_sin = std::vector<float>(1024);
  NoiseTables() {
    for (int i = 0; i < 1024; ++i) {
      const double angle = (i + 0.5) * 2 * M_PI / 1024;
      circle_cos[i] = static_cast<float>(std::cos(angle));
      circle_sin[i] = static_cast<float>(std::sin(angle));
    }
  }
};

const NoiseTables& Tables() {
  static const NoiseTables tables;
  return tables;
}

// A standard normal from 16 uniform bits (inverse-CDF sampling: |e| <= 4.17).
template <typename Gather>
LIDARSHOP_LANES_INLINE F8 NormalFrom16Bits(const float* quantiles, U8 bits, Gather gather) {
  return gather(quantiles, reinterpret_cast<const I8&>(bits));
}

// Rotation (row-major 3x3) times a vector.
LIDARSHOP_LANES_INLINE void Rotate(const float* m, F8 x, F8 y, F8 z, F8* out_x, F8* out_y, F8* out_z) {
  *out_x = m[0] * x + m[1] * y + m[2] * z;
  *out_y = m[3] * x + m[4] * y + m[5] * z;
  *out_z = m[6] * x + m[7] * y + m[8] * z;
}

// The first `count` lanes of `values` to destination[0 .. count) (all 8 in one store when count is 8).
template <typename T, typename V>
LIDARSHOP_LANES_INLINE void StoreFirst(T* destination, V values, int count) {
  if (count == kWidth) {
    lanes::Store(destination, values);
  } else {
    for (int lane = 0; lane < count; ++lane) destination[lane] = values[lane];
  }
}

// Packed colours (scanner/texture.h: PackRgb) to `count` consecutive 3-byte cells.
LIDARSHOP_LANES_INLINE void StoreColors(cv::Vec3b* destination, U8 rgb, int count) {
  using B32 = uint8_t __attribute__((vector_size(32)));
  const B32 bytes = reinterpret_cast<const B32&>(rgb);
  const B32 triples = __builtin_shufflevector(bytes, bytes, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 16, 17,
                                              18, 20, 21, 22, 24, 25, 26, 28, 29, 30, 0, 0, 0, 0, 0, 0, 0, 0);
  if (count == kWidth) {  // (constant sizes: plain stores, no rep movs)
    std::memcpy(static_cast<void*>(destination), &triples, 3 * kWidth);
  } else {
    std::memcpy(static_cast<void*>(destination), &triples, 3 * count);
  }
}

// Lanes (x, y, z) to `count` consecutive 3-float cells.
LIDARSHOP_LANES_INLINE void StoreTriples(cv::Vec3f* destination, F8 x, F8 y, F8 z, int count) {
  float interleaved[3 * kWidth];
  for (int lane = 0; lane < kWidth; ++lane) {
    interleaved[3 * lane] = x[lane];
    interleaved[3 * lane + 1] = y[lane];
    interleaved[3 * lane + 2] = z[lane];
  }
  if (count == kWidth) {  // (a constant size: plain vector stores, no rep movs)
    std::memcpy(static_cast<void*>(destination), interleaved, sizeof(interleaved));
  } else {
    std::memcpy(static_cast<void*>(destination), interleaved, sizeof(float) * 3 * count);
  }
}

LIDARSHOP_LANES_INLINE void PrepareBandBody(const ShadeSetup& setup, int row0, int rows, Band& band,
                                            Scan& scan) {
  using D4 = double __attribute__((vector_size(32)));
  using F4 = float __attribute__((vector_size(16)));
  // float(a * b) for 8 columns, the products in double.
  auto products = [](double a, const double* b) __attribute__((always_inline)) {
    const F4 low = __builtin_convertvector(a * lanes::Load<D4>(b), F4);
    const F4 high = __builtin_convertvector(a * lanes::Load<D4>(b + 4), F4);
    return F8(__builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7));
  };
  const int cols = band.cols;
  for (int r = 0; r < rows; ++r) {
    const int row = row0 + r;
    const double cos_elevation = setup.cos_elevation[row];
    const F8 z = Splat(static_cast<float>(setup.sin_elevation[row]));
    cv::Vec3f* direction = scan.direction.ptr<cv::Vec3f>(row);
    for (int col = 0; col < cols; col += kWidth) {
      const int k = r * cols + col;
      const F8 x = products(cos_elevation, setup.sin_azimuth.data() + col);
      const F8 y = products(cos_elevation, setup.cos_azimuth.data() + col);
      lanes::Store(band.d_x.data() + k, x);
      lanes::Store(band.d_y.data() + k, y);
      lanes::Store(band.d_z.data() + k, z);
      F8 world_x, world_y, world_z;
      Rotate(setup.world_from_scanner, x, y, z, &world_x, &world_y, &world_z);
      lanes::Store(band.w_x.data() + k, world_x);
      lanes::Store(band.w_y.data() + k, world_y);
      lanes::Store(band.w_z.data() + k, world_z);
      StoreTriples(direction + col, x, y, z, std::min(kWidth, cols - col));
    }
  }
}

// The noise of one image row, into the band's noise arrays: e_los, and e_orth · (cos ψ, sin ψ) along (b1,
// b2). (A loop of its own: short enough for the CPU to overlap the hash -> table chains of
// several steps, which the long shading loop cannot.)
template <typename Gather>
LIDARSHOP_LANES_INLINE void DrawNoise(const ShadeSetup& setup, int row, int cols, Band& band, Gather gather) {
  const NoiseTables& tables = Tables();
  const I8 lane_index = {0, 1, 2, 3, 4, 5, 6, 7};
  const int32_t* geometry = band.geometry.data() + (row - band.row0) * cols;
  for (int col = 0; col < cols; col += kWidth) {
    if (!lanes::Any(lanes::Load<I8>(geometry + col) >= 0)) continue;  // no return here: no noise needed
    // One 32-bit hash per cell gives 16 bits for e_los and 16 for e_orth, a second one 10 bits for ψ.
    const U8 cell =
        lanes::SplatUint(static_cast<uint32_t>(row * cols + col)) + reinterpret_cast<const U8&>(lane_index);
    const U8 bits = lanes::Mix32(cell ^ setup.noise_seed[0]);
    lanes::Store(band.noise_los.data() + col,
                 setup.los_sigma * NormalFrom16Bits(tables.quantiles.data(), bits & 0xFFFFu, gather));
    if (setup.orthogonal_sigma > 0) {
      const U8 psi_bits = lanes::Mix32(bits ^ setup.noise_seed[1]) & 0x3FFu;
      const I8 psi = reinterpret_cast<const I8&>(psi_bits);
      const F8 e_orth =
          setup.orthogonal_sigma * NormalFrom16Bits(tables.quantiles.data(), bits >> 16, gather);
      lanes::Store(band.noise_b1.data() + col, e_orth * gather(tables.circle_cos.data(), psi));
      lanes::Store(band.noise_b2.data() + col, e_orth * gather(tables.circle_sin.data(), psi));
    }
  }
}

// Bit i set where lane i of `mask` is set.
LIDARSHOP_LANES_INLINE unsigned LaneBits(I8 mask) {
  unsigned bits = 0;
  for (int lane = 0; lane < kWidth; ++lane) bits |= (mask[lane] & 1u) << lane;
  return bits;
}

// What a group of 8 cells takes from its objects (most groups lie on one object).
struct GroupSurface {
  F8 n_x, n_y, n_z;  // normal, world frame, any length
  I8 label = lanes::SplatInt(kNoLabel);
  F8 reflectivity = {};
  U8 rgb = {};
  int textured[kWidth];  // objects with a procedural texture
  int num_textured = 0;
};

// Per-object values of the group's hit lanes `pending`, object by object; per-cell objects (curved
// triangles, mesh colours, image textures) are resolved lane by lane (in registers: a vector load of values
// just stored one by one would stall store forwarding).
LIDARSHOP_LANES_INLINE GroupSurface SurfaceOfGroup(const ShadeSetup& setup, const Band& band, int k, I8 id,
                                                   unsigned pending) {
  GroupSurface surface;
  surface.n_x = lanes::Load<F8>(band.n_x.data() + k);
  surface.n_y = lanes::Load<F8>(band.n_y.data() + k);
  surface.n_z = lanes::Load<F8>(band.n_z.data() + k);
  while (pending != 0) {
    const int object_id = id[__builtin_ctz(pending)];
    const ObjectData& object = setup.objects[object_id];
    const I8 mine = id == object_id;
    const unsigned mine_bits = LaneBits(mine) & pending;
    pending &= ~mine_bits;
    surface.label = mine ? lanes::SplatInt(object.label) : surface.label;
    surface.reflectivity = mine ? Splat(object.material.reflectivity) : surface.reflectivity;
    if (object.per_cell) {
      for (unsigned bits = mine_bits; bits != 0; bits &= bits - 1) {
        const int lane = __builtin_ctz(bits);
        Eigen::Vector3f normal(surface.n_x[lane], surface.n_y[lane], surface.n_z[lane]);
        surface.rgb[lane] =
            PerCellSurface(object, band.primitive[k + lane], band.u[k + lane], band.v[k + lane], &normal);
        surface.n_x[lane] = normal.x();
        surface.n_y[lane] = normal.y();
        surface.n_z[lane] = normal.z();
      }
    } else {
      surface.rgb = mine ? lanes::SplatUint(PackRgb(object.material.color)) : surface.rgb;
    }
    if (object.material.texture != TextureKind::kNone) surface.textured[surface.num_textured++] = object_id;
  }
  return surface;
}

template <typename Gather>
LIDARSHOP_LANES_INLINE int64_t ShadeBandBody(const ShadeSetup& setup, Band& band, Scan& scan, Gather gather) {
  const int cols = band.cols;
  const float max_step = static_cast<float>(ShadeSetup::kFalloffSteps);
  const I8 lane_index = {0, 1, 2, 3, 4, 5, 6, 7};
  int64_t returns = 0;
  for (int r = 0; r < band.rows; ++r) {
    const int row = band.row0 + r;
    uint8_t* valid_out = scan.valid.ptr<uint8_t>(row);
    float* range_out = scan.range.ptr<float>(row);
    cv::Vec3f* point_out = scan.point.ptr<cv::Vec3f>(row);
    float* intensity_out = scan.intensity.ptr<float>(row);
    cv::Vec3b* color_out = scan.color.ptr<cv::Vec3b>(row);
    int32_t* label_out = scan.label.ptr<int32_t>(row);
    cv::Vec3f* normal_out = scan.normal.ptr<cv::Vec3f>(row);
    float* true_range_out = scan.true_range.ptr<float>(row);
    if (setup.noisy) DrawNoise(setup, row, cols, band, gather);
    for (int col = 0; col < cols; col += kWidth) {
      const int k = r * cols + col, count = std::min(kWidth, cols - col);
      const I8 id = lanes::Load<I8>(band.geometry.data() + k);
      const I8 hit = (id >= 0) & (lane_index < count);
      const unsigned hit_bits = LaneBits(hit);
      returns += __builtin_popcount(hit_bits);
      const F8 zero = F8{};
      if (hit_bits == 0) {  // no return in the whole group (sky, or beyond the maximum range)
        StoreFirst(valid_out + col, lanes::LowBytes(lanes::I8{}), count);
        StoreFirst(range_out + col, zero, count);
        StoreTriples(point_out + col, zero, zero, zero, count);
        StoreFirst(intensity_out + col, Splat(0.5f), count);
        StoreColors(color_out + col, U8{}, count);
        StoreFirst(label_out + col, lanes::SplatInt(kNoLabel), count);
        StoreTriples(normal_out + col, zero, zero, zero, count);
        StoreFirst(true_range_out + col, zero, count);
        continue;
      }
      const GroupSurface surface = SurfaceOfGroup(setup, band, k, id, hit_bits);

      // The unit normal, facing the scanner.
      const F8 t = lanes::Load<F8>(band.t.data() + k);
      F8 n_x = surface.n_x, n_y = surface.n_y, n_z = surface.n_z;
      // (A miss's normal is undefined, maybe zero or stale: its lanes are masked below.)
      const F8 inverse_norm = 1.0f / lanes::Sqrt(n_x * n_x + n_y * n_y + n_z * n_z);
      n_x *= inverse_norm;
      n_y *= inverse_norm;
      n_z *= inverse_norm;
      const F8 w_x = lanes::Load<F8>(band.w_x.data() + k), w_y = lanes::Load<F8>(band.w_y.data() + k),
               w_z = lanes::Load<F8>(band.w_z.data() + k);
      F8 n_dot_d = n_x * w_x + n_y * w_y + n_z * w_z;
      const I8 away = n_dot_d > 0.0f;
      n_x = away ? -n_x : n_x;
      n_y = away ? -n_y : n_y;
      n_z = away ? -n_z : n_z;
      n_dot_d = away ? -n_dot_d : n_dot_d;
      const F8 cos_incidence = lanes::Min(-n_dot_d, Splat(1.0f));

      // The point, with noise.
      const F8 d_x = lanes::Load<F8>(band.d_x.data() + k), d_y = lanes::Load<F8>(band.d_y.data() + k),
               d_z = lanes::Load<F8>(band.d_z.data() + k);
      F8 p_x = t * d_x, p_y = t * d_y, p_z = t * d_z, range = t;
      if (setup.noisy) {
        const F8 e_los = lanes::Load<F8>(band.noise_los.data() + col);
        p_x += e_los * d_x;
        p_y += e_los * d_y;
        p_z += e_los * d_z;
        if (setup.orthogonal_sigma > 0) {
          // b1 = (cos θ, -sin θ, 0) (horizontal, ⟂ d for every elevation), b2 = d × b1.
          const F8 ca = lanes::Load<F8>(setup.cos_azimuth_f.data() + col);
          const F8 sa = lanes::Load<F8>(setup.sin_azimuth_f.data() + col);
          const F8 along_b1 = lanes::Load<F8>(band.noise_b1.data() + col);
          const F8 along_b2 = lanes::Load<F8>(band.noise_b2.data() + col);
          p_x += along_b1 * ca + along_b2 * (d_z * sa);
          p_y += along_b1 * -sa + along_b2 * (d_z * ca);
          p_z += along_b2 * -(d_x * sa + d_y * ca);
        }
        range = lanes::Sqrt(p_x * p_x + p_y * p_y + p_z * p_z);
      }

      // Procedural textures, object by object.
      U8 rgb = surface.rgb;
      for (int i = 0; i < surface.num_textured; ++i) {
        const int object_id = surface.textured[i];
        const ShadeSetup::TextureFrame& frame = setup.texture_frames[object_id];
        F8 q_x, q_y, q_z, m_x, m_y, m_z;
        Rotate(frame.to_texture, frame.offset[0] + t * w_x, frame.offset[1] + t * w_y,
               frame.offset[2] + t * w_z, &q_x, &q_y, &q_z);
        Rotate(frame.to_texture, n_x, n_y, n_z, &m_x, &m_y, &m_z);
        // Triplanar coordinates (scanner/texture.h: TriplanarCoordinates).
        const F8 a_x = lanes::Abs(m_x), a_y = lanes::Abs(m_y), a_z = lanes::Abs(m_z);
        const I8 z_major = (a_z >= a_x) & (a_z >= a_y), x_major = a_x >= a_y;
        const F8 u = z_major ? q_x : (x_major ? q_y : q_x);
        const F8 v = z_major ? q_y : q_z;
        // The ray's footprint on the surface (band-limits the texture: no moiré at range).
        const F8 footprint = t * setup.angular_step_rad / lanes::Max(cos_incidence, Splat(0.02f));
        const float inverse_scale = frame.inverse_scale;
        const U8 textured = texture_internal::Pack(texture_internal::TextureLanes(
            setup.objects[object_id].material.texture, u * inverse_scale, v * inverse_scale,
            footprint * inverse_scale, texture_internal::Unpack(rgb)));
        rgb = id == object_id ? textured : rgb;
      }

      // Intensity, from the colour.
      const I8 channels = reinterpret_cast<const I8&>(rgb);
      const F8 luminance = (0.299f * ToFloat(channels & 0xFF) + 0.587f * ToFloat(channels >> 8 & 0xFF) +
                            0.114f * ToFloat(channels >> 16 & 0xFF)) /
                           255.0f;
      const F8 step = lanes::Clamp(t * setup.inverse_falloff_step, 0.0f, max_step);
      const I8 step_index = ToInt(hit ? step : zero);
      const F8 low = gather(setup.falloff.data(), step_index);
      const F8 attenuation =
          low + (step - ToFloat(step_index)) * (gather(setup.falloff.data(), step_index + 1) - low);
      const F8 intensity = lanes::Clamp(
          surface.reflectivity * (0.5f + luminance) * lanes::Max(cos_incidence, zero) * attenuation, 0.0f,
          1.0f);

      F8 ns_x, ns_y, ns_z;
      Rotate(setup.scanner_from_world, n_x, n_y, n_z, &ns_x, &ns_y, &ns_z);
      StoreFirst(valid_out + col, lanes::LowBytes(hit & kValid), count);
      StoreFirst(range_out + col, hit ? range : zero, count);
      StoreTriples(point_out + col, hit ? p_x : zero, hit ? p_y : zero, hit ? p_z : zero, count);
      StoreFirst(intensity_out + col, hit ? intensity : Splat(0.5f), count);
      StoreColors(color_out + col, hit ? rgb : U8{}, count);
      StoreFirst(label_out + col, surface.label, count);
      StoreTriples(normal_out + col, hit ? ns_x : zero, hit ? ns_y : zero, hit ? ns_z : zero, count);
      StoreFirst(true_range_out + col, hit ? t : zero, count);
    }
  }
  return returns;
}

__attribute__((target("avx2"))) void PrepareBandAvx2(const ShadeSetup& setup, int row0, int rows, Band& band,
                                                     Scan& scan) {
  PrepareBandBody(setup, row0, rows, band, scan);
}
void PrepareBandBaseline(const ShadeSetup& setup, int row0, int rows, Band& band, Scan& scan) {
  PrepareBandBody(setup, row0, rows, band, scan);
}
__attribute__((target("avx2"), flatten)) int64_t ShadeBandAvx2(const ShadeSetup& setup, Band& band,
                                                               Scan& scan) {
  return ShadeBandBody(setup, band, scan, lanes::Avx2FloatGather());
}
int64_t ShadeBandBaseline(const ShadeSetup& setup, Band& band, Scan& scan) {
  return ShadeBandBody(setup, band, scan, lanes::FloatGather());
}

bool UseAvx2(SimdPath path) { return path == SimdPath::kAvx2 && BestSimdPath() == SimdPath::kAvx2; }

}  // namespace

uint32_t PerCellSurface(const ObjectData& object, int triangle, float u, float v, Eigen::Vector3f* normal) {
  const TriangleMesh& mesh = object.mesh_in_world;
  const float w = 1.0f - u - v;
  if (!object.smooth.empty() && object.smooth[triangle]) {
    const Eigen::Vector3i& corners = mesh.triangles[triangle];
    const Eigen::Vector3f smooth = w * mesh.vertex_normals[corners[0]] + u * mesh.vertex_normals[corners[1]] +
                                   v * mesh.vertex_normals[corners[2]];
    if (smooth.squaredNorm() > 1e-12f) *normal = smooth;  // else keep the geometric normal
  }
  Rgb8 surface = object.material.color;
  if (!mesh.triangle_colors.empty()) {
    surface = mesh.triangle_colors[triangle];
  } else if (!mesh.vertex_colors.empty()) {
    const Eigen::Vector3i& corners = mesh.triangles[triangle];
    const Eigen::Vector3f mixed = w * mesh.vertex_colors[corners[0]].cast<float>() +
                                  u * mesh.vertex_colors[corners[1]].cast<float>() +
                                  v * mesh.vertex_colors[corners[2]].cast<float>();
    surface = (mixed.array() + 0.5f).cast<uint8_t>();
  }
  if (object.has_texture_image && object.material.texture == TextureKind::kNone) {
    const Eigen::Vector3i& tc = mesh.triangle_texcoords[triangle];
    const Eigen::Vector2f st =
        w * mesh.texcoords[tc[0]] + u * mesh.texcoords[tc[1]] + v * mesh.texcoords[tc[2]];
    surface = SampleImageTexture(mesh.texture, st.x(), st.y());
  }
  return PackRgb(surface);
}

ObjectData MakeObjectData(const SceneObject& object) {
  ObjectData data;
  data.mesh_in_world = MeshInWorld(object);
  data.material = object.material;
  data.label = object.label;
  data.has_texture_image = !object.mesh.texture.empty() && !object.mesh.triangle_texcoords.empty();
  data.Prepare(object.world_from_object);
  return data;
}

void ObjectData::Prepare(const Eigen::Matrix4d& world_from_object) {
  const Eigen::Matrix3d linear = world_from_object.topLeftCorner<3, 3>();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();  // the scale-free part
  texture_from_world_rotation = rotation.transpose().cast<float>();
  world_origin_of_object = world_from_object.topRightCorner<3, 1>().cast<float>();
  const TriangleMesh& mesh = mesh_in_world;
  smooth.clear();
  if (!mesh.vertex_normals.empty()) {
    smooth.resize(mesh.triangles.size(), 0);
    bool any = false;
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      const Eigen::Vector3i& t = mesh.triangles[f];
      const Eigen::Vector3f face = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                       .normalized();
      for (int corner = 0; corner < 3; ++corner) {
        if (mesh.vertex_normals[t[corner]].dot(face) < 1.0f - 1e-6f) smooth[f] = 1;
      }
      any = any || smooth[f];
    }
    if (!any) smooth.clear();
  }
  per_cell = !smooth.empty() || !mesh.triangle_colors.empty() || !mesh.vertex_colors.empty() ||
             (has_texture_image && material.texture == TextureKind::kNone);
}

ShadeSetup::ShadeSetup(const std::vector<ObjectData>& object_data, const ScannerOptions& options,
                       const ScanGrid& grid, const Eigen::Matrix4d& world_from_scanner_pose)
    : objects(object_data.data()) {
  const int rows = options.rows, cols = options.columns;
  for (const ObjectData& object : object_data) {
    TextureFrame& frame = texture_frames.emplace_back();
    for (int i = 0; i < 3; ++i) {
      frame.offset[i] = static_cast<float>(options.position[i]) - object.world_origin_of_object[i];
      for (int j = 0; j < 3; ++j) frame.to_texture[3 * i + j] = object.texture_from_world_rotation(i, j);
    }
    frame.inverse_scale = 1.0f / object.material.texture_scale;
  }
  const Eigen::Matrix3f rotation = world_from_scanner_pose.topLeftCorner<3, 3>().cast<float>();
  for (int i = 0; i < 3; ++i) {
    origin[i] = static_cast<float>(options.position[i]);
    for (int j = 0; j < 3; ++j) {
      world_from_scanner[3 * i + j] = rotation(i, j);
      scanner_from_world[3 * i + j] = rotation(j, i);
    }
  }
  los_sigma = static_cast<float>(options.los_noise_sigma_m);
  orthogonal_sigma = static_cast<float>(options.orthogonal_noise_sigma_m);
  noisy = los_sigma > 0 || orthogonal_sigma > 0;
  // Two 32-bit seeds from the 64-bit one (SplitMix64's finalizer).
  uint64_t key = options.seed + 0x9E3779B97F4A7C15ull;
  key = (key ^ (key >> 30)) * 0xBF58476D1CE4E5B9ull;
  key = (key ^ (key >> 27)) * 0x94D049BB133111EBull;
  key ^= key >> 31;
  noise_seed[0] = static_cast<uint32_t>(key);
  noise_seed[1] = static_cast<uint32_t>(key >> 32);

  const size_t padded_cols = (cols + kWidth - 1) / kWidth * kWidth;
  sin_azimuth.assign(padded_cols, 0.0);
  cos_azimuth.assign(padded_cols, 0.0);
  sin_azimuth_f.assign(padded_cols, 0.0f);
  cos_azimuth_f.assign(padded_cols, 0.0f);
  for (int col = 0; col < cols; ++col) {
    sin_azimuth[col] = std::sin(grid.azimuth_rad[col]);
    cos_azimuth[col] = std::cos(grid.azimuth_rad[col]);
    sin_azimuth_f[col] = static_cast<float>(sin_azimuth[col]);
    cos_azimuth_f[col] = static_cast<float>(cos_azimuth[col]);
  }
  for (int row = 0; row < rows; ++row) {
    sin_elevation.push_back(std::sin(grid.elevation_rad[row]));
    cos_elevation.push_back(std::cos(grid.elevation_rad[row]));
  }
  falloff.resize(kFalloffSteps + 2);
  for (int i = 0; i < kFalloffSteps + 2; ++i) {
    falloff[i] =
        static_cast<float>(std::exp(-i * options.max_range_m / kFalloffSteps / options.intensity_falloff_m));
  }
  inverse_falloff_step = static_cast<float>(kFalloffSteps / options.max_range_m);
  const double azimuth_step = cols > 1 ? std::abs(grid.azimuth_rad[1] - grid.azimuth_rad[0]) : 0.0;
  const double elevation_step = rows > 1 ? std::abs(grid.elevation_rad[1] - grid.elevation_rad[0]) : 0.0;
  angular_step_rad =
      options.filter_textures ? static_cast<float>(std::max(azimuth_step, elevation_step)) : 0.0f;
}

void Band::Resize(int new_cols) {
  if (cols == new_cols) return;
  cols = new_cols;
  const size_t n = static_cast<size_t>(4) * cols + kWidth;
  for (auto* array :
       {&d_x, &d_y, &d_z, &w_x, &w_y, &w_z, &t, &u, &v, &n_x, &n_y, &n_z, &noise_los, &noise_b1, &noise_b2}) {
    array->assign(n, 0.0f);
  }
  geometry.assign(n, -1);  // the padding stays "no return"
  primitive.assign(n, -1);
}

void PrepareBand(const ShadeSetup& setup, int row0, int rows, Band* band, Scan* scan, SimdPath path) {
  band->row0 = row0;
  band->rows = rows;
  if (UseAvx2(path)) {
    PrepareBandAvx2(setup, row0, rows, *band, *scan);
  } else {
    PrepareBandBaseline(setup, row0, rows, *band, *scan);
  }
}

int64_t ShadeBand(const ShadeSetup& setup, Band* band, Scan* scan, SimdPath path) {
  return UseAvx2(path) ? ShadeBandAvx2(setup, *band, *scan) : ShadeBandBaseline(setup, *band, *scan);
}

}  // namespace lidarshop::scanner_internal
