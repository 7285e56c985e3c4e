// Procedural surface textures of the synthetic scanner, at a realistic scale in metres, deterministic (hashes
// of lattice coordinates, no global state), cheap enough to evaluate once per ray.
//
//   checker  squares of `scale` metres (default 1 m), the base colour and a darker shade of it
//   grass    green base (default RGB 74 112 42), blade-scale noise (3 cm), clumps (0.4 m), dry patches (3 m)
//   gravel   stones of about 3 cm on a staggered grid, grey shades, dark gaps between stones
//   brick    0.215 x 0.065 m bricks with 10 mm mortar joints in a running bond, per-brick shade variation
//
// Surface coordinates come from a triplanar projection in the object frame (metres, not scaled): the two axes
// perpendicular to the dominant axis of the surface normal, with z as the vertical coordinate on walls so
// that brick courses are horizontal.
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "lidarshop/geometry/mesh.h"
#include "lidarshop/util/options_fwd.h"
#include "lidarshop/util/simd.h"

namespace lidarshop {

enum class TextureKind { kNone, kChecker, kGrass, kGravel, kBrick };
template <>
const EnumInfo& EnumInfoOf<TextureKind>();

// "checker", "grass", "gravel", "brick"; throws InputError naming `what` and field 'texture' otherwise.
TextureKind ParseTextureKind(const std::string& name, const std::string& what);
// The colour a texture uses when the object gives none.
Rgb8 DefaultTextureColor(TextureKind kind);

// (u, v) in metres on the surface through `point_in_object` with normal `normal_in_object`.
inline Eigen::Vector2f TriplanarCoordinates(const Eigen::Vector3f& point_in_object,
                                            const Eigen::Vector3f& normal_in_object) {
  const Eigen::Vector3f a = normal_in_object.cwiseAbs();
  if (a.z() >= a.x() && a.z() >= a.y()) return {point_in_object.x(), point_in_object.y()};
  if (a.x() >= a.y()) return {point_in_object.y(), point_in_object.z()};
  return {point_in_object.x(), point_in_object.z()};
}

// Colour of `kind` at surface coordinates (u, v) in metres, divided by `scale` (1 = the realistic size
// above). `base` is the main colour (the brick, the grass, the light checker square).
//
// `footprint_m` band-limits the texture to what one ray can resolve (anti-aliasing, no moiré at range): the
// width of the ray's footprint on the surface in metres, range · angular step / cos(incidence). Each detail
// level of period (feature size) s keeps full contrast while footprint <= s / 4 and fades linearly to its
// mean colour at footprint >= s / 2 (the Nyquist limit of the ray spacing), coarse levels staying while fine
// ones fade: grass blades (3 cm) -> clumps (0.4 m) -> dry patches (3 m); gravel stones (3 cm); brick speckle
// and mortar joints (1-3 cm) -> per-brick shade (7.5 cm courses); checker squares (`scale`). The means are
// the area averages of each level (computed once by sampling the full-detail texture). 0 = point sampling.
Rgb8 EvaluateTexture(TextureKind kind, float u, float v, Rgb8 base, float scale = 1.0f,
                     float footprint_m = 0.0f);

// An 8-bit RGB colour packed as r | g << 8 | b << 16 (what the batch below reads and writes).
inline uint32_t PackRgb(Rgb8 color) { return color[0] | color[1] << 8 | color[2] << 16; }
inline Rgb8 UnpackRgb(uint32_t rgb) { return Rgb8(rgb & 0xFF, rgb >> 8 & 0xFF, rgb >> 16 & 0xFF); }

// EvaluateTexture for `count` points at once (8 per SIMD step): rgb[i] = the colour at (u[i], v[i]) with
// base colour base_rgb[i] (packed) and footprint footprint_m[i]. Both paths give identical colours.
void EvaluateTextures(TextureKind kind, float scale, int count, const float* u, const float* v,
                      const float* footprint_m, const uint32_t* base_rgb, uint32_t* rgb,
                      SimdPath path = BestSimdPath());

// Nearest-texel lookup of an image texture (CV_8UC3 RGB) at (s, t), (0, 0) = bottom left, wrapping.
Rgb8 SampleImageTexture(const cv::Mat& texture, float s, float t);

}  // namespace lidarshop
