// The ground under a scan: the plane a second viewpoint keeps level (render/render_view.h SideView's up). A scan's
// own up (the scanner's z, an RGB-D camera's -y) is only the sensor's; a camera that looks down at a table is
// tilted against it, and orbiting about the camera's up makes the table lean. The ground's normal is the up a
// person expects when the scan shows a ground.
#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

struct GroundPlane {
  Eigen::Vector3d normal_in_world;  // unit, on the sensor's side (the sensor is above the ground)
  double share = 0;                 // of the returns used that lie on it, (0, 1]
  double tilt_deg = 0;              // angle between the normal and the scan's up (ScanUpInWorld)
};

// The ground when the scan shows one: of the three largest RANSAC planes through the returns (every cell not
// set in `exclude`, CV_8U or empty; at most 50,000 returns taken on a fixed stride; inliers within 1 % of the
// returns' median range), the largest one that holds at least 15 % of the returns, whose normal is within 60° of
// the scan's up and that lies below the sensor. std::nullopt otherwise (a wall, a scan without returns, ...).
// Deterministic (a fixed seed), so that two scans that differ only inside `exclude` find the same ground.
std::optional<GroundPlane> FindGround(const Scan& scan, const cv::Mat& exclude = cv::Mat());

}  // namespace lidarshop
