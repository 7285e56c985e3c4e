// Internal to the scanner module: the procedural textures of scanner/texture.h, eight points per call, as
// GCC vector-extension lanes (util/simd.h) that the scanner's shading inlines into both of its SIMD paths.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/simd.h"

namespace lidarshop::texture_internal {

using lanes::Any;
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
  return lanes::Mix32(reinterpret_cast<U8&>(x) * 0x8da6b343u ^ reinterpret_cast<U8&>(y) * 0xd8163841u ^
                      salt * 0xcb1ab31fu);
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

// Contrast weight of a detail level of period `size` under a footprint (see EvaluateTexture): 1 for
// footprint <= size / 4, 0 for footprint >= size / 2, linear between.
LIDARSHOP_LANES_INLINE F8 Fade(float size, F8 footprint) {
  return lanes::Clamp(2.0f - (4.0f / size) * footprint, 0.0f, 1.0f);
}

inline constexpr float kGravelSize = 0.03f;
inline constexpr float kCourseHeight = 0.075f, kBrickPitch = 0.225f, kJoint = 0.01f;
inline const Rgb8 kMortar(188, 182, 170);

// The area-mean colour of gravel as a factor of its base colour (computed once, texture.cc).
const Eigen::Vector3f& GravelMeanFactor();

// Eight lanes of EvaluateTexture, (u, v) and footprint in texture units (metres / scale). The gravel mean is
// read only where some lane fades (MeanFactor samples gravel with footprint 0 before the factor exists).
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
      // Where every lane sees only the mean (far ground), skip the stones: a zero weight makes the detail
      // drop out exactly, so the colours are the same either way.
      if (!Any(weight > 0.0f)) {
        const Eigen::Vector3f& factor = GravelMeanFactor();
        return MixRgb({factor[0] * base.r, factor[1] * base.g, factor[2] * base.b}, base, weight);
      }
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
      // (Faded levels are skipped where every lane has faded them: a zero weight drops them out exactly.)
      const F8 brick_shade =
          Any(brick_weight > 0.0f)
              ? 0.8f + 0.35f * (0.5f + brick_weight * (Hash01(ToInt(column), ToInt(course), 31) - 0.5f))
              : Splat(0.8f + 0.35f * 0.5f);
      // Joints and speckle averaged over the footprint: the mortar and the brick in proportion.
      const Colors mortar = Splat(kMortar);
      const Colors brick = Shade(base, brick_shade);
      const Colors mean = {kMortarFraction * mortar.r + (1 - kMortarFraction) * brick.r,
                           kMortarFraction * mortar.g + (1 - kMortarFraction) * brick.g,
                           kMortarFraction * mortar.b + (1 - kMortarFraction) * brick.b};
      if (!Any(fine_weight > 0.0f)) return MixRgb(mean, brick, fine_weight);
      const F8 speckle = Hash01(ToInt(lanes::Floor(u * 66.0f)), ToInt(lanes::Floor(v * 66.0f)), 32);
      const Colors detail = Select((in_u < kJoint) | (in_v < kJoint), mortar,
                                   Shade(base, brick_shade + 0.12f * fine_weight * (speckle - 0.5f)));
      return MixRgb(mean, detail, fine_weight);
    }
  }
  return base;
}

LIDARSHOP_LANES_INLINE Colors Unpack(lanes::U8 packed) {
  const I8 channels = reinterpret_cast<const I8&>(packed);
  return {ToFloat(channels & 0xFF), ToFloat(channels >> 8 & 0xFF), ToFloat(channels >> 16 & 0xFF)};
}
LIDARSHOP_LANES_INLINE lanes::U8 Pack(const Colors& color) {
  const I8 packed = ToInt(color.r) | ToInt(color.g) << 8 | ToInt(color.b) << 16;
  return reinterpret_cast<const lanes::U8&>(packed);
}

}  // namespace lidarshop::texture_internal
