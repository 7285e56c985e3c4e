// The photos of a synthetic station: what a scanner's own camera takes around it, as real rigs store them
// in E57 files (images2D) — one spherical panorama, or a cube map of six square pinhole faces — with the
// scene's own colours (scanner/photo.h), a camera centre offset from the scanner's, and an exposure that
// differs from shot to shot. Ground truth for colouring scans from their station's images (recolor/).
//
// Poses: the camera centre is `camera_height_m` above the scanner centre along the scanner's z axis. The
// panorama's frame is the scanner frame's axes (geometry/camera_model.h: its centre column looks along the
// scanner's +y). The cube faces are 90° pinhole cameras (x right, y down, z forward) looking along the
// scanner's +y ("front"), +x ("right"), −y ("back"), −x ("left"), each upright, then +z ("up") and −z
// ("down"), the top of both towards the front.
//
// Exposure: photo 0 has gain 1; photo i > 0 has gain 1 + d (2 u − 1), d = max_gain_deviation and u uniform
// in [0, 1) from a hash of (seed, i). A pixel is round(gain · rendered colour), saturated to [0, 255].
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class StationPhotoKind { kSphere, kCube };

struct StationPhotoOptions {
  StationPhotoKind kind = StationPhotoKind::kSphere;
  int size_px = 512;                // cube: a face's side; sphere: the panorama's height (its width is twice)
  double camera_height_m = 0.15;    // camera centre above the scanner centre (scanner z), metres
  double max_gain_deviation = 0.3;  // photos after the first: gain in [1 − d, 1 + d]
  uint64_t seed = 1;                // draws the gains
  PhotoOptions photo;               // rendering (background, samples per pixel)
  void Check() const;               // throws OptionsError
};

struct StationPhoto {
  std::string name;  // "panorama", or the cube face: "front", "right", "back", "left", "up", "down"
  Camera camera;     // world frame
  cv::Mat image;     // CV_8UC3 RGB, with the gain applied
  double gain = 1;   // exposure relative to photo 0
};

// A photo as `lidarshop scan --json` lists it ("photos"): its name, camera model, size and exposure.
struct StationPhotoSummary {
  std::string name;                 // StationPhoto::name
  std::string model;                // the camera model's name (CameraModelName): "spherical", "pinhole"
  int width_px = 0, height_px = 0;  // the image's size, pixels
  double gain = 1;                  // exposure relative to photo 0
  std::optional<int> station;       // the station (index in the scene) it was taken at: a site's photos only
};
template <>
const StructInfo& InfoOf<StationPhotoSummary>();

// The summary of `photo`; `station` is the station's index for a site (nullopt for a one-station scene).
StationPhotoSummary SummarizeStationPhoto(const StationPhoto& photo, std::optional<int> station);

// Renders the station photos of a scanner at `scanner` (its pose) in `scene`.
std::vector<StationPhoto> RenderStationPhotos(const SceneDescription& scene, const ScannerOptions& scanner,
                                              const StationPhotoOptions& options);

// Their images2D entries (io/e57_image_camera.h), each belonging to the data3D entry `scan_index`.
std::vector<E57Image> StationPhotosToE57(const std::vector<StationPhoto>& photos, int scan_index = 0);

}  // namespace lidarshop
