// A pinhole camera with lens distortion: the model photos are taken with (recolouring, thesis 3.2).
//
// Frames: the camera frame has x right, y down and z forward (the viewing direction), metres;
// `world_from_camera` maps it to the world. Pixels are continuous coordinates with x right and y down, (0, 0)
// the top-left corner of the photo and (0.5, 0.5) the centre of its first pixel (OpenCV puts that centre at
// (0, 0): subtract 0.5 before calling OpenCV, add it back after).
//
// Projection of a point X_c = (x, y, z) of the camera frame, z > 0 (Brown–Conrady, OpenCV's order):
//   (a, b) = (x / z, y / z), r² = a² + b²,
//   a' = a (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 a b + p2 (r² + 2 a²),
//   b' = b (1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2 b²) + 2 p2 a b,
//   u = fx a' + skew b' + cx,  v = fy b' + cy   (pixels).
//
// JSON form (ReadCameraJson / CameraToJson; `skew_px` and `distortion` may be left out, they default to 0):
//   {"width_px": 1024, "height_px": 768, "fx_px": 800, "fy_px": 800, "cx_px": 512, "cy_px": 384,
//    "skew_px": 0, "distortion": {"k1": 0, "k2": 0, "k3": 0, "p1": 0, "p2": 0},
//    "world_from_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
//    "units": {"intrinsics": "pixels", "world_from_camera": "metres",
//              "camera_frame": "x right, y down, z forward"}}
// A "model" key other than "pinhole" is refused: fisheye, spherical and cylindrical cameras are read by
// geometry/camera_model.h.
#pragma once

#include <string>

#include <Eigen/Core>

namespace lidarshop {

struct PinholeCamera {
  int width_px = 0, height_px = 0;  // image size
  double fx_px = 0, fy_px = 0;      // focal lengths
  double cx_px = 0, cy_px = 0;      // principal point (continuous pixel coordinates, see above)
  double skew_px = 0;               // K(0, 1)
  double k1 = 0, k2 = 0, k3 = 0;    // radial distortion (unitless)
  double p1 = 0, p2 = 0;            // tangential distortion (unitless)
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();  // rigid, metres

  // The 3x3 intrinsic matrix [fx skew cx; 0 fy cy; 0 0 1].
  Eigen::Matrix3d K() const;
  Eigen::Vector3d center_in_world() const { return world_from_camera.topRightCorner<3, 1>(); }
  bool has_distortion() const { return k1 != 0 || k2 != 0 || k3 != 0 || p1 != 0 || p2 != 0; }
  // Throws InputError naming `what` when a field is out of range (size <= 0, focal <= 0, non-finite values,
  // a world_from_camera that is not rigid).
  void Check(const std::string& what = "camera") const;
};

// An undistorted camera at `eye` looking at `target` (world z up: the image's y runs down
// along -z), focal length from the horizontal field of view, principal point at the image
// centre. For scenes, tests and examples.
PinholeCamera CameraLookingAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int width_px,
                              int height_px, double horizontal_fov_deg);

// Normalized image coordinates (a, b) -> distorted ones (a', b'), the formula above.
Eigen::Vector2d DistortNormalized(const PinholeCamera& camera, const Eigen::Vector2d& normalized);
// The inverse, by fixed-point iteration (converges for the distortions of real lenses).
Eigen::Vector2d UndistortNormalized(const PinholeCamera& camera, const Eigen::Vector2d& distorted);

// Pixel of a point of the camera frame; false (and `pixel_px` untouched) when z <= 0 (behind the camera).
bool ProjectCameraPoint(const PinholeCamera& camera, const Eigen::Vector3d& point_in_camera,
                        Eigen::Vector2d* pixel_px);
// Pixel of a world point.
bool ProjectWorldPoint(const PinholeCamera& camera, const Eigen::Vector3d& point_in_world,
                       Eigen::Vector2d* pixel_px);
// The ray of a pixel: a direction in the camera frame with z = 1 (so that depth · ray is the point).
Eigen::Vector3d UnprojectPixel(const PinholeCamera& camera, const Eigen::Vector2d& pixel_px);
// True when the pixel lies inside the image, [0, width) x [0, height).
bool InsideImage(const PinholeCamera& camera, const Eigen::Vector2d& pixel_px);

// JSON text of the form above (pretty printed).
std::string CameraToJson(const PinholeCamera& camera);
// Parses the JSON form; throws InputError naming `what` and the field (missing, wrong type, out of range).
PinholeCamera ParseCameraJson(const std::string& json_text, const std::string& what);
PinholeCamera ReadCameraJson(const std::string& path);
void WriteCameraJson(const std::string& path, const PinholeCamera& camera);  // atomic

}  // namespace lidarshop
