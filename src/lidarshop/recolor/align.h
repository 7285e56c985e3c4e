// The other correspondence modes of the thesis's selection tool (3.2.1): scan <-> scan landmarks give a rigid
// (optionally scaled) transform, photo <-> photo pairs give a homography or a fundamental matrix.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// What a photo <-> photo fit estimates.
enum class PhotoModel { kHomography, kFundamental };
// What a landmark fit estimates: a rigid transform, or a similarity when a uniform scale is allowed.
enum class LandmarkModel { kRigid, kSimilarity };

// The parameters of `lidarshop align` and of the editor's landmark and photo-pair routes (docs/api.md): the
// same keys, ranges and defaults for both (util/options.h; recolor/options_info.cc).
struct AlignOptions {
  bool scale = false;                          // landmarks: allow a uniform scale (similarity)
  PhotoModel model = PhotoModel::kHomography;  // photo pairs: the model fitted
  double threshold_px = 3.0;                   // photo pairs: RANSAC inlier threshold, pixels; (0, 1000]
};

// A landmark picked in two scans (or a scan and a model): the same physical point in each frame, metres.
struct PointPair {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

// Described (model, scale, rms_m, residual_m; the matrix is not JSON: the CLI writes it as text, the server as
// target_from_source_column_major).
struct LandmarkAlignment {
  LandmarkModel model = LandmarkModel::kRigid;
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

// Described (model, rms_px, error_px, inlier; the matrix as for LandmarkAlignment).
struct PhotoPairModel {
  PhotoModel model = PhotoModel::kHomography;
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
// The model `options.model` with `options.threshold_px` (validated first: OptionsFieldError for a bad value).
PhotoPairModel EstimatePhotoModel(std::span<const PixelPair> pairs, const AlignOptions& options,
                                  const std::string& what);

template <>
const EnumInfo& EnumInfoOf<PhotoModel>();
template <>
const EnumInfo& EnumInfoOf<LandmarkModel>();
template <>
const StructInfo& InfoOf<AlignOptions>();
template <>
const StructInfo& InfoOf<LandmarkAlignment>();
template <>
const StructInfo& InfoOf<PhotoPairModel>();

}  // namespace lidarshop
