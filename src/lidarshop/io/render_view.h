// A picture of a scan's points seen from another viewpoint: a pinhole camera anywhere in the world, points
// drawn as small squares with a depth buffer. Where the scan's own ray image shows every fill as plausible,
// this view shows what the scanner could not: floating patches, bent surfaces, sampling artefacts.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct PointViewOptions {
  Eigen::Vector3d eye_in_world = Eigen::Vector3d::Zero();      // camera centre, metres
  Eigen::Vector3d target_in_world = Eigen::Vector3d::UnitY();  // the point the camera looks at, metres
  double field_of_view_deg = 60.0;                             // horizontal, degrees, in (0, 170)
  int width_px = 640, height_px = 480;                         // picture size, >= 16
  int point_size_px = 2;                                       // side of each drawn point, pixels, >= 1
  // Synthesized points tinted magenta (share of the tint, 0 = drawn like measured points).
  double synthesized_tint = 0.0;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<PointViewOptions>();

// CV_8UC3 RGB, black background. Points take the scan's colour, or grey intensity when it has none, or a plain
// light grey (200) when it has neither. World z
// is up in the picture.
cv::Mat RenderPointView(const Scan& scan, const PointViewOptions& options);

// A second viewpoint for a region of the scan (CV_8U non-zero cells, e.g. a hole): the camera stands at the
// scanner's height, `angle_deg` around the region's centre from the scanner's side, at the same distance, and
// looks at the centre.
PointViewOptions SideView(const Scan& scan, const cv::Mat& region, double angle_deg);

}  // namespace lidarshop
