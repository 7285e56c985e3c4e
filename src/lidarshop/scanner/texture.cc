#include "lidarshop/scanner/texture.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

inline uint32_t Hash(int32_t x, int32_t y, uint32_t salt) {
  uint32_t h =
      static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^ salt * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// floor without SSE4.1's roundss (the Debian baseline is x86-64): a truncation and a compare.
inline float FastFloor(float x) {
  const float t = static_cast<float>(static_cast<int32_t>(x));
  return t > x ? t - 1.0f : t;
}

// Uniform in [0, 1).
inline float Hash01(int32_t x, int32_t y, uint32_t salt) {
  return (Hash(x, y, salt) >> 8) * (1.0f / 16777216.0f);
}

// Smooth value noise in [0, 1) with unit lattice spacing.
inline float ValueNoise(float x, float y, uint32_t salt) {
  const float fx = FastFloor(x), fy = FastFloor(y);
  const int32_t ix = static_cast<int32_t>(fx), iy = static_cast<int32_t>(fy);
  float tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const float a = Hash01(ix, iy, salt), b = Hash01(ix + 1, iy, salt);
  const float c = Hash01(ix, iy + 1, salt), d = Hash01(ix + 1, iy + 1, salt);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

inline Rgb8 Shade(Rgb8 color, float factor) {
  return Rgb8(static_cast<uint8_t>(std::clamp(color[0] * factor, 0.0f, 255.0f)),
              static_cast<uint8_t>(std::clamp(color[1] * factor, 0.0f, 255.0f)),
              static_cast<uint8_t>(std::clamp(color[2] * factor, 0.0f, 255.0f)));
}

inline Rgb8 Mix(Rgb8 a, Rgb8 b, float t) {
  return Rgb8(static_cast<uint8_t>(a[0] + (b[0] - a[0]) * t), static_cast<uint8_t>(a[1] + (b[1] - a[1]) * t),
              static_cast<uint8_t>(a[2] + (b[2] - a[2]) * t));
}

// Contrast weight of a detail level of period `size` under a footprint (see EvaluateTexture): 1 for
// footprint <= size / 4, 0 for footprint >= size / 2, linear between.
// (A multiplication by the constant 4 / size: no division in the per-ray path.)
inline float Fade(float size, float footprint) {
  return std::clamp(2.0f - (4.0f / size) * footprint, 0.0f, 1.0f);
}

inline Rgb8 MixRgb(const Eigen::Vector3f& mean, Rgb8 detail, float weight) {
  return Rgb8(static_cast<uint8_t>(mean[0] + (detail[0] - mean[0]) * weight + 0.5f),
              static_cast<uint8_t>(mean[1] + (detail[1] - mean[1]) * weight + 0.5f),
              static_cast<uint8_t>(mean[2] + (detail[2] - mean[2]) * weight + 0.5f));
}

constexpr float kGravelSize = 0.03f;
constexpr float kCourseHeight = 0.075f, kBrickPitch = 0.225f, kJoint = 0.01f;
const Rgb8 kMortar(188, 182, 170);

// Per-channel mean of the full-detail texture with a mid-grey base (100, 100, 100), as a factor of the base
// colour: the area average over 512 x 512 samples of a 15 x 15 m patch. Shade() is linear in the base below
// its clamp, so mean(base) = factor * base.
Eigen::Vector3f MeanFactor(TextureKind kind) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  constexpr int kSamples = 512;
  for (int i = 0; i < kSamples; ++i) {
    for (int j = 0; j < kSamples; ++j) {
      const Rgb8 c = EvaluateTexture(kind, 0.02937f * i + 0.0011f * j, 0.02911f * j + 0.0007f * i,
                                     Rgb8(100, 100, 100), 1.0f, 0.0f);
      sum += c.cast<double>();
    }
  }
  return (sum / (100.0 * kSamples * kSamples)).cast<float>();
}

const Eigen::Vector3f& GravelMeanFactor() {
  static const Eigen::Vector3f factor = MeanFactor(TextureKind::kGravel);
  return factor;
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

Rgb8 EvaluateTexture(TextureKind kind, float u, float v, Rgb8 base, float scale, float footprint_m) {
  const float inverse_scale = 1.0f / scale;
  u *= inverse_scale;
  v *= inverse_scale;
  const float footprint = footprint_m * inverse_scale;  // in texture units
  switch (kind) {
    case TextureKind::kNone:
      return base;
    case TextureKind::kChecker: {
      const float weight = Fade(2.0f, footprint);  // period of the pattern: two squares
      const Rgb8 dark = Shade(base, 0.3f);
      if (weight <= 0.0f) return MixRgb(0.5f * (base.cast<float>() + dark.cast<float>()), base, 0.0f);
      const int parity = (static_cast<int>(FastFloor(u)) + static_cast<int>(FastFloor(v))) & 1;
      if (weight >= 1.0f) return parity ? dark : base;
      return MixRgb(0.5f * (base.cast<float>() + dark.cast<float>()), parity ? dark : base, weight);
    }
    case TextureKind::kGrass: {
      const float blade_weight = Fade(1.0f / 33.0f, footprint);
      const float clump_weight = Fade(1.0f / 2.5f, footprint);
      const float dry_weight = Fade(1.0f / 0.33f, footprint);
      float blades = 0.5f, clumps = 0.5f, dry = 0.5f;
      if (blade_weight > 0.0f) {
        blades += blade_weight * (Hash01(static_cast<int32_t>(FastFloor(u * 33.0f)),
                                         static_cast<int32_t>(FastFloor(v * 33.0f)), 11) -
                                  0.5f);
      }
      if (clump_weight > 0.0f) clumps += clump_weight * (ValueNoise(u * 2.5f, v * 2.5f, 12) - 0.5f);
      if (dry_weight > 0.0f) dry += dry_weight * (ValueNoise(u * 0.33f, v * 0.33f, 13) - 0.5f);
      const Rgb8 green = Shade(base, 0.55f + 0.5f * blades + 0.25f * (clumps - 0.5f));
      const float dryness = std::clamp((dry - 0.6f) * 2.5f, 0.0f, 0.6f);
      return Mix(green, Rgb8(150, 140, 78), dryness);
    }
    case TextureKind::kGravel: {
      const float weight = Fade(kGravelSize, footprint);
      // (The mean is only read when fading: MeanFactor samples this case with footprint 0.)
      if (weight <= 0.0f) return MixRgb(GravelMeanFactor().cwiseProduct(base.cast<float>()), base, 0.0f);
      const float row = FastFloor(v * (1.0f / kGravelSize));
      const float shifted = u * (1.0f / kGravelSize) + 0.5f * (static_cast<int>(row) & 1);
      const float col = FastFloor(shifted);
      const float fu = shifted - col, fv = v * (1.0f / kGravelSize) - row;
      // One hash per stone: 8 bits each for the gap width, the shade and the warmth.
      const uint32_t h = Hash(static_cast<int32_t>(col), static_cast<int32_t>(row), 21);
      const float edge = std::min(std::min(fu, 1 - fu), std::min(fv, 1 - fv));
      Rgb8 stone;
      if (edge < 0.08f + 0.1f / 255.0f * (h & 0xFFu)) {
        stone = Shade(base, 0.35f);
      } else {
        const float shade = 0.65f + 0.6f / 255.0f * ((h >> 8) & 0xFFu);
        const float warm = ((h >> 16) & 0xFFu) / 255.0f - 0.5f;
        stone = Shade(base, shade);
        stone[0] = static_cast<uint8_t>(std::clamp(stone[0] * (1 + 0.15f * warm), 0.0f, 255.0f));
        stone[2] = static_cast<uint8_t>(std::clamp(stone[2] * (1 - 0.15f * warm), 0.0f, 255.0f));
      }
      return weight >= 1.0f ? stone
                            : MixRgb(GravelMeanFactor().cwiseProduct(base.cast<float>()), stone, weight);
    }
    case TextureKind::kBrick: {
      // Mortar covers this fraction of the wall.
      constexpr float kMortarFraction =
          1.0f - (kBrickPitch - kJoint) * (kCourseHeight - kJoint) / (kBrickPitch * kCourseHeight);
      const float brick_weight = Fade(kCourseHeight, footprint);  // per-brick shades
      const float fine_weight = Fade(3.0f * kJoint, footprint);   // joints (1 cm) and speckle (1.5 cm)
      const Eigen::Vector3f mortar = kMortar.cast<float>();
      if (brick_weight <= 0.0f) {  // the whole wall's mean
        const Eigen::Vector3f wall =
            kMortarFraction * mortar + (1 - kMortarFraction) * Shade(base, 0.8f + 0.35f * 0.5f).cast<float>();
        return MixRgb(wall, base, 0.0f);
      }
      const float course = FastFloor(v * (1.0f / kCourseHeight));
      const float shifted = u + (static_cast<int>(course) & 1) * (kBrickPitch / 2);
      const float column = FastFloor(shifted * (1.0f / kBrickPitch));
      const float in_u = shifted - column * kBrickPitch, in_v = v - course * kCourseHeight;
      const int32_t ci = static_cast<int32_t>(column), ri = static_cast<int32_t>(course);
      // Per-brick shade (faded to its mean 0.975 at range) plus a 1.5 cm speckle.
      const float brick_shade = 0.8f + 0.35f * (0.5f + brick_weight * (Hash01(ci, ri, 31) - 0.5f));
      if (fine_weight <= 0.0f) {  // joints and speckle averaged over the footprint
        const Eigen::Vector3f mean =
            kMortarFraction * mortar + (1 - kMortarFraction) * Shade(base, brick_shade).cast<float>();
        return MixRgb(mean, base, 0.0f);
      }
      const float speckle =
          Hash01(static_cast<int32_t>(FastFloor(u * 66.0f)), static_cast<int32_t>(FastFloor(v * 66.0f)), 32);
      const Rgb8 detail = (in_u < kJoint || in_v < kJoint)
                              ? kMortar
                              : Shade(base, brick_shade + 0.12f * fine_weight * (speckle - 0.5f));
      if (fine_weight >= 1.0f) return detail;
      const Eigen::Vector3f mean =
          kMortarFraction * mortar + (1 - kMortarFraction) * Shade(base, brick_shade).cast<float>();
      return MixRgb(mean, detail, fine_weight);
    }
  }
  return base;
}

Rgb8 SampleImageTexture(const cv::Mat& texture, float s, float t) {
  if (texture.empty()) return Rgb8(180, 180, 180);
  s -= FastFloor(s);
  t -= FastFloor(t);
  const int col = std::clamp(static_cast<int>(s * texture.cols), 0, texture.cols - 1);
  const int row = std::clamp(static_cast<int>((1 - t) * texture.rows), 0, texture.rows - 1);
  const cv::Vec3b& pixel = texture.at<cv::Vec3b>(row, col);
  return Rgb8(pixel[0], pixel[1], pixel[2]);
}

}  // namespace lidarshop
