// The scan rendered as a camera would see it, for the automatic resection (auto_resection.h) and its
// silhouette alignment (silhouette_alignment.h): internal to the recolor module.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/scan/scan.h"

namespace lidarshop::auto_resection_internal {

inline constexpr double kDegPerRad = 180.0 / M_PI;

// Which channel of the scan a rendering shows (as grey).
enum class Shade { kColorElseIntensity, kIntensityElseColor };

// The scan's valid points in the world frame with their grey value, and the grid that joins them.
struct ScanSamples {
  std::vector<Eigen::Vector3d> point_in_world;
  std::vector<float> grey;
  std::vector<float> range_m;  // from the scanner centre
  cv::Mat index;               // CV_32S, the scan's grid: the sample of each cell, -1 without a return
  double cell_angle_rad = 0;
  Eigen::Vector3d scanner_in_world = Eigen::Vector3d::Zero();
};

double Median(std::vector<double> values);

// Throws InputError naming `what` when the scan has neither colour nor intensity.
ScanSamples SamplesOf(const Scan& scan, const std::string& what, Shade shade = Shade::kColorElseIntensity);

// A rendering of the scan: grey values and, per pixel, the surface point seen through the pixel's centre.
struct View {
  PinholeCamera camera;
  cv::Mat grey;            // CV_8U
  cv::Mat point_from_eye;  // CV_32FC3: the point seen minus the camera centre, world axes, metres
  cv::Mat depth;           // CV_32F: along the optical axis, +inf where nothing is seen
};

// Neighbouring returns whose ranges differ by more than this ratio lie on different surfaces (a depth edge):
// no triangle joins them. Ground 40 m from a scanner 1.5 m high changes range by 4 % per 0.09° row.
constexpr double kMaxRangeRatio = 1.15;

// The scan's grid mesh (two triangles per 2 x 2 cells whose returns lie on one surface; three returns make
// one) rasterized with a z-buffer; grey and point interpolated perspective-correctly.
View Render(const ScanSamples& samples, const PinholeCamera& camera);

// The intrinsics of `camera` for an image `width_px` x `height_px` (pose kept).
PinholeCamera Scaled(const PinholeCamera& camera, int width_px, int height_px);

// Sets camera's pose from OpenCV's rvec and tvec (the world in the camera's frame, as solvePnP gives it).
void SetPose(const cv::Mat& rvec, const cv::Mat& tvec, PinholeCamera* camera);

}  // namespace lidarshop::auto_resection_internal
