// The other correspondence modes of the thesis's selection tool (3.2.1): scan <-> scan landmarks give a rigid
// (optionally scaled) transform, photo <-> photo pairs give a homography or a fundamental matrix.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace lidarshop {

// A landmark picked in two scans (or a scan and a model): the same physical point in each frame, metres.
struct PointPair {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

struct LandmarkAlignment {
  Eigen::Matrix4d target_from_source = Eigen::Matrix4d::Identity();  // s·R·x + t
  double scale = 1.0;
  std::vector<double> residual_m;  // per pair: |T·source − target|
  double rms_m = 0;
};

// Least-squares rigid (or similarity, `with_scale`) transform, Umeyama (1991) through Eigen::umeyama. Throws
// InputError naming `what` for fewer than 3 pairs, non-finite values or collinear landmarks.
LandmarkAlignment AlignLandmarks(std::span<const PointPair> pairs, bool with_scale, const std::string& what);

// The same point in two photos, continuous pixel coordinates (geometry/camera.h).
struct PixelPair {
  Eigen::Vector2d pixel_a = Eigen::Vector2d::Zero();
  Eigen::Vector2d pixel_b = Eigen::Vector2d::Zero();
};

struct PhotoPairModel {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();  // H (b = H a) or F (b^T F a = 0), pixel coordinates
  std::vector<double>
      error_px;  // per pair: |H a − b| (homography) or the distance of b to the epipolar line F a
  std::vector<uint8_t> inlier;
  double rms_px = 0;  // over the inliers
};

// OpenCV's findHomography (RANSAC, >= 4 pairs) and findFundamentalMat (RANSAC, >= 8 pairs) with a pixel
// threshold. Throws InputError naming `what` for too few pairs, non-finite values or no model found.
PhotoPairModel EstimateHomography(std::span<const PixelPair> pairs, double threshold_px,
                                  const std::string& what);
PhotoPairModel EstimateFundamental(std::span<const PixelPair> pairs, double threshold_px,
                                   const std::string& what);

}  // namespace lidarshop
