// The synthetic camera: what a camera (a pinhole, geometry/camera.h, or a fisheye, a spherical or a cylindrical
// panorama, geometry/camera_model.h) sees in a scene, with the scanner's own
// colours (material, triangle and vertex colours, image textures, procedural textures band-limited to the
// pixel's footprint: scanner/shade.h, scanner/texture.h), unlit like the scanner's colour channel. Ground
// truth for resectioning and recolouring (recolor/): tests know the true camera of the photo.
//
// Each pixel (x, y) casts the ray of its centre (x + 0.5, y + 0.5) through the camera's distortion (or
// `samples_per_axis`² rays on a regular sub-grid, averaged) with Embree (raycast/), from the camera centre.
// Pixels without a ray (beyond a fisheye's reach, past a panorama's pole) are background.
#pragma once

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct PhotoOptions {
  Rgb8 background = Rgb8(0, 0, 0);  // colour of rays that hit nothing (sky)
  int samples_per_axis = 1;         // 1..8: rays per pixel = samples², box-filtered (anti-aliased edges)
  double max_range_m = 1000.0;      // farther hits count as background, metres
  void Check() const;               // throws OptionsError
};
template <>
const StructInfo& InfoOf<PhotoOptions>();

struct Photo {
  cv::Mat image;    // CV_8UC3 RGB, camera height x width
  cv::Mat label;    // CV_32S: the label of the object seen by the pixel centre, kNoLabel for background
  cv::Mat depth_m;  // CV_32F: distance from the camera centre to the surface seen by the pixel centre, +inf
                    // for background
};

// A synthetic photo in brief: the result of `lidarshop photo --json`. Described.
struct PhotoSummary {
  std::string model;  // the camera model's name
  int width_px = 0, height_px = 0;
  int64_t scene_pixels = 0;  // pixels whose centre sees the scene (not the background)
};
PhotoSummary SummarizePhoto(const Photo& photo, const Camera& camera);
template <>
const StructInfo& InfoOf<PhotoSummary>();

// Renders the scene seen by `camera` (camera.Check() must pass; throws InputError otherwise).
Photo RenderPhoto(const SceneDescription& scene, const PinholeCamera& camera,
                  const PhotoOptions& options = {});
// Any camera model (camera.Check() must pass).
Photo RenderPhoto(const SceneDescription& scene, const Camera& camera, const PhotoOptions& options = {});

}  // namespace lidarshop
