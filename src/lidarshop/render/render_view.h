// A picture of a scan's points seen from another viewpoint: a pinhole camera anywhere in the world, points
// drawn as small squares with a depth buffer. Where the scan's own ray image shows every fill as plausible,
// this view shows what the scanner could not: floating patches, bent surfaces, sampling artefacts.
//
// Which way is up. Every organized scan keeps row 0 = top = highest elevation in its scanner frame, so the
// scanner's z axis is the picture's up for every scan lidarshop reads: a terrestrial scanner's vertical axis
// (PTX, E57, PLY/PCD written by lidarshop), and for an organized camera-like cloud (an RGB-D or stereo PCD,
// 640 x 480, points in an optical frame) the camera's -y, because the PCD reader makes its scanner frame from
// the optical one ((x, y, z)_optical = (x, -z, y)_scanner, io/pcd.cc). ScanUpInWorld gives that axis in the
// world frame, and second viewpoints keep it up, so a camera-like cloud seen from its own camera (SideView at
// 0°) looks like its own image, and one seen from 30° off is not rolled. When the scan shows a ground
// (pointset/ground.h FindGround: a large plane below the sensor within 60° of its up), `render --orbit` takes
// the ground's normal as up instead, so a table a camera looks down at stays level as the camera turns.
//
// The camera file (`render --camera CAM.json`, `--write-camera CAM.json`), metres and degrees, world frame:
//   {"eye": [x, y, z], "target": [x, y, z], "up": [x, y, z], "fov_deg": 60, "width": 640, "height": 480}
// `up` need not be orthogonal to the line of sight (it is made so; it must not be parallel to it); `fov_deg`
// is the horizontal field of view. Unknown keys are refused (a misspelt key must not be ignored).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct PointViewOptions {
  Eigen::Vector3d eye_in_world = Eigen::Vector3d::Zero();      // camera centre, metres
  Eigen::Vector3d target_in_world = Eigen::Vector3d::UnitY();  // the point the camera looks at, metres
  // Picture-up direction in the world (any length, not parallel to the line of sight); zero = the scan's own
  // up (ScanUpInWorld).
  Eigen::Vector3d up_in_world = Eigen::Vector3d::Zero();
  double field_of_view_deg = 60.0;      // horizontal, degrees, in (0, 170)
  int width_px = 640, height_px = 480;  // picture size, >= 16
  int point_size_px = 2;                // side of each drawn point, pixels, >= 1
  // Synthesized points tinted magenta (share of the tint, 0 = drawn like measured points).
  double synthesized_tint = 0.0;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<PointViewOptions>();

// The scanner's z axis in the world frame (unit): the up of every picture of the scan (see the top).
Eigen::Vector3d ScanUpInWorld(const Scan& scan);

// CV_8UC3 RGB, black background. Points take the scan's colour, or grey intensity when it has none, or a plain
// light grey (200) when it has neither. `up_in_world` (or the scan's up) is up in the picture.
cv::Mat RenderPointView(const Scan& scan, const PointViewOptions& options);

// A second viewpoint for a region of the scan (CV_8U non-zero cells, e.g. a hole): the camera turns
// `angle_deg` about the up axis through the region's centre, starting from the scanner's position, and looks
// at the centre; up is `up_in_world` (e.g. the ground's normal, pointset/ground.h), zero = the scan's up.
// The centre lies along the mean direction of the returns in a ring around the region (3, 10, 30 or 100 cells
// wide, the first that holds returns), at their median range. Neither depends on what the region's cells hold
// (not even their grid directions, which a grid fitted to the returns moves), so the camera is the same before
// and after an edit inside the region (a fill, a removal): pictures of both match pixel for pixel where the
// edited points do not show. Without a ring (a region that covers every cell, or one in the sky) the centre
// is the median of the region's returns on each world axis (or of all returns; 1 m ahead of the scanner
// without any).
PointViewOptions SideView(const Scan& scan, const cv::Mat& region, double angle_deg,
                          const Eigen::Vector3d& up_in_world = Eigen::Vector3d::Zero());

// The camera file (see the top) and `render --json`'s "camera": metres and degrees, world frame.
struct PointViewCamera {
  std::vector<double> eye;        // camera centre x, y, z, metres
  std::vector<double> target;     // the point looked at x, y, z, metres
  std::vector<double> up;         // the picture's up x, y, z (any length)
  double fov_deg = 60.0;          // horizontal field of view, degrees
  int width = 640, height = 480;  // picture size, pixels
};
template <>
const StructInfo& InfoOf<PointViewCamera>();

// The camera of `view`: its eye, target, up (resolved against `scan` when zero), field of view and size.
PointViewCamera CameraOf(const PointViewOptions& view, const Scan& scan);

// The ground whose normal a second viewpoint took as up (`render --orbit`, pointset/ground.h GroundPlane).
struct ViewGround {
  double share = 0;     // of the returns used that lie on the ground, (0, 1]
  double tilt_deg = 0;  // angle between its normal and the scan's up, degrees
};
template <>
const StructInfo& InfoOf<ViewGround>();

// What `render --eye | --orbit | --camera` drew (its --json).
struct PointViewResult {
  std::optional<std::string> up_from;   // --orbit: "ground" (the ground's normal is up) or "scan" (its up)
  std::optional<ViewGround> ground;     // --orbit with a ground: the plane whose normal is up
  std::string output;                   // the picture written
  int width_px = 0, height_px = 0;      // its size, pixels
  std::vector<double> eye_in_world;     // = camera.eye, metres
  std::vector<double> target_in_world;  // = camera.target, metres
  std::vector<double> up_in_world;      // = camera.up
  PointViewCamera camera;               // the camera drawn with (as --write-camera writes it)
};
template <>
const StructInfo& InfoOf<PointViewResult>();
// Parses a camera file's text into `view` (eye, target, up, field of view, size; the rest is kept). Throws
// InputError naming `what` and the field.
void ParseCameraJson(const std::string& text, const std::string& what, PointViewOptions* view);

}  // namespace lidarshop
