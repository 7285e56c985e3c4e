#include "lidarshop/scanner/texture.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/simd.h"

namespace lidarshop {
namespace {

using lanes::F8;
using lanes::I8;
using lanes::Splat;
using lanes::ToFloat;
using lanes::ToInt;
using lanes::U8;

// A colour per lane, each channel in [0, 255].
struct Colors {
  F8 r, g, b;
};

LIDARSHOP_LANES_INLINE U8 Hash(I8 x, I8 y, uint32_t salt) {
  U8 h = reinterpret_cast<U8&>(x) * 0x8da6b343u ^ reinterpret_cast<U8&>(y) * 0xd8163841u ^ salt * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// Uniform in [0, 1).
LIDARSHOP_LANES_INLINE F8 Hash01(I8 x, I8 y, uint32_t salt) {
  const U8 bits = Hash(x, y, salt) >> 8;
  return ToFloat(reinterpret_cast<const I8&>(bits)) * (1.0f / 16777216.0f);
}

// Smooth value noise in [0, 1) with unit lattice spacing.
LIDARSHOP_LANES_INLINE F8 ValueNoise(F8 x, F8 y, uint32_t salt) {
  const F8 fx = lanes::Floor(x), fy = lanes::Floor(y);
  const I8 ix = ToInt(fx), iy = ToInt(fy);
  F8 tx = x - fx, ty = y - fy;
  tx = tx * tx * (3.0f - 2.0f * tx);
  ty = ty * ty * (3.0f - 2.0f * ty);
  const F8 a = Hash01(ix, iy, salt), b = Hash01(ix + 1, iy, salt);
  const F8 c = Hash01(ix, iy + 1, salt), d = Hash01(ix + 1, iy + 1, salt);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

// uint8(clamp(x, 0, 255)): the truncation of an 8-bit channel.
LIDARSHOP_LANES_INLINE F8 Channel(F8 x) { return ToFloat(ToInt(lanes::Clamp(x, 0.0f, 255.0f))); }

LIDARSHOP_LANES_INLINE Colors Shade(const Colors& color, F8 factor) {
  return {Channel(color.r * factor), Channel(color.g * factor), Channel(color.b * factor)};
}

LIDARSHOP_LANES_INLINE Colors Mix(const Colors& a, const Colors& b, F8 t) {
  return {ToFloat(ToInt(a.r + (b.r - a.r) * t)), ToFloat(ToInt(a.g + (b.g - a.g) * t)),
          ToFloat(ToInt(a.b + (b.b - a.b) * t))};
}

// The mean colour with `weight` of the detail (rounded to 8 bits).
LIDARSHOP_LANES_INLINE Colors MixRgb(const Colors& mean, const Colors& detail, F8 weight) {
  return {ToFloat(ToInt(mean.r + (detail.r - mean.r) * weight + 0.5f)),
          ToFloat(ToInt(mean.g + (detail.g - mean.g) * weight + 0.5f)),
          ToFloat(ToInt(mean.b + (detail.b - mean.b) * weight + 0.5f))};
}

LIDARSHOP_LANES_INLINE Colors Select(I8 mask, const Colors& a, const Colors& b) {
  return {mask ? a.r : b.r, mask ? a.g : b.g, mask ? a.b : b.b};
}

LIDARSHOP_LANES_INLINE Colors Splat(Rgb8 color) {
  return {Splat(color[0]), Splat(color[1]), Splat(color[2])};
}

LIDARSHOP_LANES_INLINE bool Any(I8 mask) {
  int any = 0;
  for (int lane = 0; lane < lanes::kWidth; ++lane) any |= mask[lane];
  return any != 0;
}

// Contrast weight of a detail level of period `size` under a footprint (see EvaluateTexture): 1 for
// footprint <= size / 4, 0 for footprint >= size / 2, linear between.
LIDARSHOP_LANES_INLINE F8 Fade(float size, F8 footprint) {
  return lanes::Clamp(2.0f - (4.0f / size) * footprint, 0.0f, 1.0f);
}

constexpr float kGravelSize = 0.03f;
constexpr float kCourseHeight = 0.075f, kBrickPitch = 0.225f, kJoint = 0.01f;
const Rgb8 kMortar(188, 182, 170);

// Per-channel mean of the full-detail texture with a mid-grey base (100, 100, 100), as a factor of the base
// colour: the area average over 512 x 512 samples of a 15 x 15 m patch. Shade() is linear in the base below
// its clamp, so mean(base) = factor * base.
Eigen::Vector3f MeanFactor(TextureKind kind) {
  constexpr int kSamples = 512;
  std::vector<float> u, v;
  for (int i = 0; i < kSamples; ++i) {
    for (int j = 0; j < kSamples; ++j) {
      u.push_back(0.02937f * i + 0.0011f * j);
      v.push_back(0.02911f * j + 0.0007f * i);
    }
  }
  const std::vector<float> footprint(u.size(), 0.0f);
  const std::vector<uint32_t> base(u.size(), PackRgb(Rgb8(100, 100, 100)));
  std::vector<uint32_t> colors(u.size());
  EvaluateTextures(kind, 1.0f, static_cast<int>(u.size()), u.data(), v.data(), footprint.data(), base.data(),
                   colors.data());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const uint32_t color : colors) sum += UnpackRgb(color).cast<double>();
  return (sum / (100.0 * kSamples * kSamples)).cast<float>();
}

const Eigen::Vector3f& GravelMeanFactor() {
  static const Eigen::Vector3f factor = MeanFactor(TextureKind::kGravel);
  return factor;
}

// Eight lanes of EvaluateTexture (footprints in texture units). `gravel_mean` is read only where some lane
// fades (MeanFactor samples gravel with footprint 0 before the factor exists).
LIDARSHOP_LANES_INLINE Colors TextureLanes(TextureKind kind, F8 u, F8 v, F8 footprint, const Colors& base) {
  switch (kind) {
    case TextureKind::kNone:
      return base;
    case TextureKind::kChecker: {
      const F8 weight = Fade(2.0f, footprint);  // period of the pattern: two squares
      const Colors dark = Shade(base, Splat(0.3f));
      const Colors mean = {0.5f * (base.r + dark.r), 0.5f * (base.g + dark.g), 0.5f * (base.b + dark.b)};
      const I8 parity = (ToInt(lanes::Floor(u)) + ToInt(lanes::Floor(v))) & 1;
      return MixRgb(mean, Select(parity != 0, dark, base), weight);
    }
    case TextureKind::kGrass: {
      const F8 blade_weight = Fade(1.0f / 33.0f, footprint);
      const F8 clump_weight = Fade(1.0f / 2.5f, footprint);
      const F8 dry_weight = Fade(1.0f / 0.33f, footprint);
      // A faded level contributes exactly its mean 0.5: skip its noise when every lane has faded it.
      F8 blades = Splat(0.5f), clumps = Splat(0.5f), dry = Splat(0.5f);
      if (Any(blade_weight > 0.0f)) {
        blades += blade_weight *
                  (Hash01(ToInt(lanes::Floor(u * 33.0f)), ToInt(lanes::Floor(v * 33.0f)), 11) - 0.5f);
      }
      if (Any(clump_weight > 0.0f)) clumps += clump_weight * (ValueNoise(u * 2.5f, v * 2.5f, 12) - 0.5f);
      if (Any(dry_weight > 0.0f)) dry += dry_weight * (ValueNoise(u * 0.33f, v * 0.33f, 13) - 0.5f);
      const Colors green = Shade(base, 0.55f + 0.5f * blades + 0.25f * (clumps - 0.5f));
      const F8 dryness = lanes::Clamp((dry - 0.6f) * 2.5f, 0.0f, 0.6f);
      return Mix(green, Splat(Rgb8(150, 140, 78)), dryness);
    }
    case TextureKind::kGravel: {
      const F8 weight = Fade(kGravelSize, footprint);
      const F8 row = lanes::Floor(v * (1.0f / kGravelSize));
      const F8 shifted = u * (1.0f / kGravelSize) + 0.5f * ToFloat(ToInt(row) & 1);
      const F8 col = lanes::Floor(shifted);
      const F8 fu = shifted - col, fv = v * (1.0f / kGravelSize) - row;
      // One hash per stone: 8 bits each for the gap width, the shade and the warmth.
      const U8 h = Hash(ToInt(col), ToInt(row), 21);
      const I8 byte0 = reinterpret_cast<const I8&>(h) & 0xFF;
      const I8 byte1 = reinterpret_cast<const I8&>(h) >> 8 & 0xFF;
      const I8 byte2 = reinterpret_cast<const I8&>(h) >> 16 & 0xFF;
      const F8 edge = lanes::Min(lanes::Min(fu, 1.0f - fu), lanes::Min(fv, 1.0f - fv));
      const F8 warm = ToFloat(byte2) / 255.0f - 0.5f;
      Colors stone = Shade(base, 0.65f + 0.6f / 255.0f * ToFloat(byte1));
      stone.r = Channel(stone.r * (1.0f + 0.15f * warm));
      stone.b = Channel(stone.b * (1.0f - 0.15f * warm));
      const Colors detail =
          Select(edge < 0.08f + 0.1f / 255.0f * ToFloat(byte0), Shade(base, Splat(0.35f)), stone);
      if (!Any(weight < 1.0f)) return detail;
      const Eigen::Vector3f& factor = GravelMeanFactor();
      return MixRgb({factor[0] * base.r, factor[1] * base.g, factor[2] * base.b}, detail, weight);
    }
    case TextureKind::kBrick: {
      // Mortar covers this fraction of the wall.
      constexpr float kMortarFraction =
          1.0f - (kBrickPitch - kJoint) * (kCourseHeight - kJoint) / (kBrickPitch * kCourseHeight);
      const F8 brick_weight = Fade(kCourseHeight, footprint);  // per-brick shades
      const F8 fine_weight = Fade(3.0f * kJoint, footprint);   // joints (1 cm) and speckle (1.5 cm)
      const F8 course = lanes::Floor(v * (1.0f / kCourseHeight));
      const F8 shifted = u + ToFloat(ToInt(course) & 1) * (kBrickPitch / 2);
      const F8 column = lanes::Floor(shifted * (1.0f / kBrickPitch));
      const F8 in_u = shifted - column * kBrickPitch, in_v = v - course * kCourseHeight;
      // Per-brick shade (faded to its mean 0.975 at range) plus a 1.5 cm speckle.
      const F8 brick_shade =
          0.8f + 0.35f * (0.5f + brick_weight * (Hash01(ToInt(column), ToInt(course), 31) - 0.5f));
      const F8 speckle = Hash01(ToInt(lanes::Floor(u * 66.0f)), ToInt(lanes::Floor(v * 66.0f)), 32);
      const Colors mortar = Splat(kMortar);
      const Colors detail = Select((in_u < kJoint) | (in_v < kJoint), mortar,
                                   Shade(base, brick_shade + 0.12f * fine_weight * (speckle - 0.5f)));
      // Joints and speckle averaged over the footprint: the mortar and the brick in proportion.
      const Colors brick = Shade(base, brick_shade);
      const Colors mean = {kMortarFraction * mortar.r + (1 - kMortarFraction) * brick.r,
                           kMortarFraction * mortar.g + (1 - kMortarFraction) * brick.g,
                           kMortarFraction * mortar.b + (1 - kMortarFraction) * brick.b};
      return MixRgb(mean, detail, fine_weight);
    }
  }
  return base;
}

// The batch loop, written once for both paths.
LIDARSHOP_LANES_INLINE void TexturesBody(TextureKind kind, float scale, int count, const float* u,
                                         const float* v, const float* footprint_m, const uint32_t* base_rgb,
                                         uint32_t* rgb) {
  const float inverse_scale = 1.0f / scale;
  constexpr int kWidth = lanes::kWidth;
  for (int begin = 0; begin < count; begin += kWidth) {
    // The last, partial group runs on padded copies.
    alignas(32) float u_lanes[kWidth] = {}, v_lanes[kWidth] = {}, footprint_lanes[kWidth] = {};
    alignas(32) uint32_t base_lanes[kWidth] = {}, out_lanes[kWidth];
    const int n = std::min(kWidth, count - begin);
    const bool full = n == kWidth;
    if (!full) {
      std::copy_n(u + begin, n, u_lanes);
      std::copy_n(v + begin, n, v_lanes);
      std::copy_n(footprint_m + begin, n, footprint_lanes);
      std::copy_n(base_rgb + begin, n, base_lanes);
    }
    const U8 packed = lanes::Load<U8>(full ? base_rgb + begin : base_lanes);
    const Colors base = {ToFloat(reinterpret_cast<const I8&>(packed) & 0xFF),
                         ToFloat(reinterpret_cast<const I8&>(packed) >> 8 & 0xFF),
                         ToFloat(reinterpret_cast<const I8&>(packed) >> 16 & 0xFF)};
    const Colors color =
        TextureLanes(kind, lanes::Load<F8>(full ? u + begin : u_lanes) * inverse_scale,
                     lanes::Load<F8>(full ? v + begin : v_lanes) * inverse_scale,
                     lanes::Load<F8>(full ? footprint_m + begin : footprint_lanes) * inverse_scale, base);
    const I8 out = ToInt(color.r) | ToInt(color.g) << 8 | ToInt(color.b) << 16;
    lanes::Store(full ? rgb + begin : out_lanes, out);
    if (!full) std::copy_n(out_lanes, n, rgb + begin);
  }
}

__attribute__((target("avx2"))) void TexturesAvx2(TextureKind kind, float scale, int count, const float* u,
                                                  const float* v, const float* footprint_m,
                                                  const uint32_t* base_rgb, uint32_t* rgb) {
  TexturesBody(kind, scale, count, u, v, footprint_m, base_rgb, rgb);
}

void TexturesBaseline(TextureKind kind, float scale, int count, const float* u, const float* v,
                      const float* footprint_m, const uint32_t* base_rgb, uint32_t* rgb) {
  TexturesBody(kind, scale, count, u, v, footprint_m, base_rgb, rgb);
}

}  // namespace

TextureKind ParseTextureKind(const std::string& name, const std::string& what) {
  if (name == "checker") return TextureKind::kChecker;
  if (name == "grass") return TextureKind::kGrass;
  if (name == "gravel") return TextureKind::kGravel;
  if (name == "brick") return TextureKind::kBrick;
  if (name == "none") return TextureKind::kNone;
  ThrowInputError(what, "", "texture",
                  fmt::format("unknown texture '{}' (checker, grass, gravel, brick)", name));
}

std::string TextureName(TextureKind kind) {
  switch (kind) {
    case TextureKind::kChecker:
      return "checker";
    case TextureKind::kGrass:
      return "grass";
    case TextureKind::kGravel:
      return "gravel";
    case TextureKind::kBrick:
      return "brick";
    case TextureKind::kNone:
      break;
  }
  return "none";
}

Rgb8 DefaultTextureColor(TextureKind kind) {
  switch (kind) {
    case TextureKind::kChecker:
      return Rgb8(220, 220, 220);
    case TextureKind::kGrass:
      return Rgb8(74, 112, 42);
    case TextureKind::kGravel:
      return Rgb8(138, 132, 122);
    case TextureKind::kBrick:
      return Rgb8(158, 68, 48);
    case TextureKind::kNone:
      break;
  }
  return Rgb8(180, 180, 180);
}

void EvaluateTextures(TextureKind kind, float scale, int count, const float* u, const float* v,
                      const float* footprint_m, const uint32_t* base_rgb, uint32_t* rgb, SimdPath path) {
  if (path == SimdPath::kAvx2 && BestSimdPath() == SimdPath::kAvx2) {
    TexturesAvx2(kind, scale, count, u, v, footprint_m, base_rgb, rgb);
  } else {
    TexturesBaseline(kind, scale, count, u, v, footprint_m, base_rgb, rgb);
  }
}

Rgb8 EvaluateTexture(TextureKind kind, float u, float v, Rgb8 base, float scale, float footprint_m) {
  const uint32_t base_rgb = PackRgb(base);
  uint32_t rgb;
  EvaluateTextures(kind, scale, 1, &u, &v, &footprint_m, &base_rgb, &rgb);
  return UnpackRgb(rgb);
}

Rgb8 SampleImageTexture(const cv::Mat& texture, float s, float t) {
  if (texture.empty()) return Rgb8(180, 180, 180);
  s -= std::floor(s);
  t -= std::floor(t);
  const int col = std::clamp(static_cast<int>(s * texture.cols), 0, texture.cols - 1);
  const int row = std::clamp(static_cast<int>((1 - t) * texture.rows), 0, texture.rows - 1);
  const cv::Vec3b& pixel = texture.at<cv::Vec3b>(row, col);
  return Rgb8(pixel[0], pixel[1], pixel[2]);
}

}  // namespace lidarshop
