// Camera models beyond the pinhole (geometry/camera.h): equidistant fisheye, spherical (equirectangular) and
// cylindrical panoramas, as terrestrial scanners' own cameras store them (E57's pinholeRepresentation,
// sphericalRepresentation and cylindricalRepresentation: io/e57.h, io/e57_image_camera.h).
//
// Pixels are continuous coordinates as for the pinhole: (0, 0) the top-left corner of the image, (0.5, 0.5)
// the centre of its first pixel, x right, y down.
//
// Camera frames (`world_from_camera` maps them to the world, metres):
// - pinhole and fisheye: x right, y down, z forward (the optical axis), as PinholeCamera.
// - spherical and cylindrical: the scanner frame's axes (ARCHITECTURE.md): z up, y forward, x right; the
//   image is laid out as a scan's ray image, so a panorama taken from the scanner centre overlays its grid:
//   column -> azimuth θ from +y, positive to the right (towards +x); row -> elevation (spherical) or height on
//   the cylinder (cylindrical), up = row 0.
//
// Projection of a point X = (x, y, z) of the camera frame to a pixel (u, v):
// - pinhole: geometry/camera.h (Brown–Conrady distortion), z > 0.
// - fisheye (equidistant, OpenCV's fisheye model): θ = atan2(√(x² + y²), z), the angle off the axis,
//   θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸), (a, b) = θd · (x, y) / √(x² + y²),
//   u = fx a + skew b + cx, v = fy b + cy. Every θ in [0, π) projects (θd must grow with θ up to there).
// - spherical: θ = atan2(x, y), φ = atan2(z, √(x² + y²)),
//   u = W/2 + θ / pixel_width_rad, v = H/2 − φ / pixel_height_rad (the centre pixel looks along +y; a full
//   panorama has W · pixel_width_rad = 2π, H · pixel_height_rad = π).
// - cylindrical (radius r, metres): θ = atan2(x, y), h = r z / √(x² + y²) the height where the ray meets the
//   cylinder, u = W/2 + θ / pixel_width_rad, v = principal_y_px − h / pixel_height_m (principal_y_px: the
//   row of the horizon, E57's principalPointY). Points on the z axis do not project.
//
// JSON form (ReadCameraModelJson / CameraModelToJson): the pinhole JSON of geometry/camera.h plus a "model"
// key, "pinhole" when absent (so every pinhole camera file reads unchanged):
//   fisheye:     {"model": "fisheye", "width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px",
//                 "skew_px" (optional), "distortion": {"k1", "k2", "k3", "k4"} (optional), "world_from_camera"}
//   spherical:   {"model": "spherical", "width_px", "height_px", "pixel_width_rad", "pixel_height_rad",
//                 "world_from_camera"}
//   cylindrical: {"model": "cylindrical", "width_px", "height_px", "pixel_width_rad", "pixel_height_m",
//                 "radius_m", "principal_y_px", "world_from_camera"}
#pragma once

#include <string>

#include <Eigen/Core>

#include "lidarshop/geometry/camera.h"

namespace lidarshop {

enum class CameraModel { kPinhole, kFisheye, kSpherical, kCylindrical };
const char* CameraModelName(CameraModel model);  // "pinhole", "fisheye", "spherical", "cylindrical"

struct Camera {
  CameraModel model = CameraModel::kPinhole;
  // Pinhole and fisheye: `pinhole` holds the size, the intrinsics (pixels) and, for the pinhole model, its
  // Brown distortion (k1, k2, k3, p1, p2). Spherical and cylindrical use its width_px and height_px only.
  // The pose is `world_from_camera` below (pinhole.world_from_camera is ignored).
  PinholeCamera pinhole;
  double fisheye_k[4] = {0, 0, 0, 0};  // fisheye: k1..k4 of θd = θ (1 + k1 θ² + ...), unitless
  double pixel_width_rad = 0;          // spherical and cylindrical: azimuth step of a column, radians
  double pixel_height_rad = 0;         // spherical: elevation step of a row, radians
  double pixel_height_m = 0;           // cylindrical: height step of a row on the cylinder, metres
  double radius_m = 0;                 // cylindrical: radius of the cylinder, metres
  double principal_y_px = 0;           // cylindrical: the row of the horizon (continuous pixels)
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();  // rigid, metres

  int width_px() const { return pinhole.width_px; }
  int height_px() const { return pinhole.height_px; }
  Eigen::Vector3d center_in_world() const { return world_from_camera.topRightCorner<3, 1>(); }
  // The angle a pixel spans near the image centre, radians (texture footprints, sampling).
  double PixelAngleRad() const;
  // Throws InputError naming `what` and the field when a value is out of range.
  void Check(const std::string& what = "camera") const;
  // The pinhole camera (model must be kPinhole; throws std::logic_error otherwise).
  PinholeCamera AsPinhole() const;
};

Camera CameraFromPinhole(const PinholeCamera& pinhole);
// A full spherical panorama (360° x 180°), width = 2 · height.
Camera SphericalPanorama(int height_px, const Eigen::Matrix4d& world_from_camera);

// Pixel of a point of the camera frame; false (and `pixel_px` untouched) when the point does not project
// (behind a pinhole camera, on the axis of a panorama, at the camera centre).
bool ProjectCameraPoint(const Camera& camera, const Eigen::Vector3d& point_in_camera,
                        Eigen::Vector2d* pixel_px);
bool ProjectWorldPoint(const Camera& camera, const Eigen::Vector3d& point_in_world,
                       Eigen::Vector2d* pixel_px);
// The unit ray of a pixel in the camera frame; false when the pixel has none (a fisheye pixel beyond the
// angle the lens reaches, a spherical row past a pole).
bool UnprojectPixel(const Camera& camera, const Eigen::Vector2d& pixel_px, Eigen::Vector3d* ray_in_camera);
bool InsideImage(const Camera& camera, const Eigen::Vector2d& pixel_px);

// JSON text of the form above (pretty printed); a pinhole camera gives CameraToJson's text plus "model".
std::string CameraModelToJson(const Camera& camera);
// Parses the JSON form; throws InputError naming `what` and the field (missing, wrong type, out of range,
// an unknown model).
Camera ParseCameraModelJson(const std::string& json_text, const std::string& what);
Camera ReadCameraModelJson(const std::string& path);
void WriteCameraModelJson(const std::string& path, const Camera& camera);  // atomic

}  // namespace lidarshop
