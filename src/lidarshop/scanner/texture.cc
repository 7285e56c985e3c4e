#include "lidarshop/scanner/texture.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/scanner/texture_lanes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/simd.h"

namespace lidarshop {

namespace texture_internal {
namespace {

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

}  // namespace

const Eigen::Vector3f& GravelMeanFactor() {
  static const Eigen::Vector3f factor = MeanFactor(TextureKind::kGravel);
  return factor;
}

}  // namespace texture_internal

namespace {

using lanes::F8;
using lanes::U8;

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
    const texture_internal::Colors color = texture_internal::TextureLanes(
        kind, lanes::Load<F8>(full ? u + begin : u_lanes) * inverse_scale,
        lanes::Load<F8>(full ? v + begin : v_lanes) * inverse_scale,
        lanes::Load<F8>(full ? footprint_m + begin : footprint_lanes) * inverse_scale,
        texture_internal::Unpack(packed));
    lanes::Store(full ? rgb + begin : out_lanes, texture_internal::Pack(color));
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
  try {
    return ParseEnum<TextureKind>(name);
  } catch (const OptionsError& error) {
    ThrowInputError(what, "", "texture", error.what());
  }
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
