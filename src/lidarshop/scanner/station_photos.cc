#include "lidarshop/scanner/station_photos.h"

#include <cmath>

#include <fmt/format.h>

#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

// SplitMix64: a well-mixed 64-bit hash (the same on every platform, unlike std:: distributions).
uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double Gain(const StationPhotoOptions& options, int index) {
  if (index == 0) return 1.0;
  const double u =
      static_cast<double>(Mix(Mix(options.seed) ^ static_cast<uint64_t>(index)) >> 11) * 0x1.0p-53;
  return 1.0 + options.max_gain_deviation * (2 * u - 1);
}

struct Face {
  const char* name;
  Eigen::Vector3d x, y, z;  // the camera's axes in the scanner frame
};

}  // namespace

void StationPhotoOptions::Check() const {
  if (size_px < 2 || size_px > 16384)
    throw OptionsError(fmt::format("the photo size must be in [2, 16384] pixels, got {}", size_px));
  if (!std::isfinite(camera_height_m) || std::abs(camera_height_m) > 100)
    throw OptionsError(fmt::format("the camera height must be within ±100 m, got {}", camera_height_m));
  if (!(max_gain_deviation >= 0 && max_gain_deviation < 1))
    throw OptionsError(fmt::format("the gain deviation must be in [0, 1), got {}", max_gain_deviation));
  photo.Check();
}

std::vector<StationPhoto> RenderStationPhotos(const SceneDescription& scene, const ScannerOptions& scanner,
                                              const StationPhotoOptions& options) {
  options.Check();
  scanner.Check();
  Eigen::Matrix4d world_from_rig = scanner.WorldFromScanner();
  world_from_rig.topRightCorner<3, 1>() +=
      world_from_rig.topLeftCorner<3, 3>() * Eigen::Vector3d(0, 0, options.camera_height_m);
  std::vector<StationPhoto> photos;
  if (options.kind == StationPhotoKind::kSphere) {
    photos.push_back({"panorama", SphericalPanorama(options.size_px, world_from_rig), {}, 1.0});
  } else {
    const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                          Z = Eigen::Vector3d::UnitZ();
    const Face faces[] = {{"front", X, -Z, Y}, {"right", -Y, -Z, X}, {"back", -X, -Z, -Y},
                          {"left", Y, -Z, -X}, {"up", -X, -Y, Z},    {"down", X, -Y, -Z}};
    for (const Face& face : faces) {
      PinholeCamera pinhole;
      pinhole.width_px = pinhole.height_px = options.size_px;
      pinhole.fx_px = pinhole.fy_px = 0.5 * options.size_px;  // 90° across
      pinhole.cx_px = pinhole.cy_px = 0.5 * options.size_px;
      Eigen::Matrix4d rig_from_camera = Eigen::Matrix4d::Identity();
      rig_from_camera.topLeftCorner<3, 3>() << face.x, face.y, face.z;
      pinhole.world_from_camera = world_from_rig * rig_from_camera;
      photos.push_back({face.name, CameraFromPinhole(pinhole), {}, 1.0});
    }
  }
  for (size_t i = 0; i < photos.size(); ++i) {
    StationPhoto& photo = photos[i];
    photo.gain = Gain(options, static_cast<int>(i));
    const Photo rendered = RenderPhoto(scene, photo.camera, options.photo);
    rendered.image.convertTo(photo.image, CV_8UC3, photo.gain);  // rounds and saturates
  }
  return photos;
}

std::vector<E57Image> StationPhotosToE57(const std::vector<StationPhoto>& photos, int scan_index) {
  std::vector<E57Image> images;
  for (const StationPhoto& photo : photos) {
    images.push_back(E57ImageOfCamera(photo.camera, photo.image, photo.name, photo.name));
    images.back().associated_scan = scan_index;
  }
  return images;
}

StationPhotoSummary SummarizeStationPhoto(const StationPhoto& photo, std::optional<int> station) {
  StationPhotoSummary summary;
  summary.name = photo.name;
  summary.model = CameraModelName(photo.camera.model);
  summary.width_px = photo.image.cols;
  summary.height_px = photo.image.rows;
  summary.gain = photo.gain;
  summary.station = station;
  return summary;
}

}  // namespace lidarshop
