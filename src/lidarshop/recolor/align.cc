#include "lidarshop/recolor/align.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

LandmarkAlignment AlignLandmarks(std::span<const PointPair> pairs, bool with_scale, const std::string& what) {
  if (pairs.size() < 3)
    ThrowInputError(what, "", "pairs",
                    fmt::format("a landmark transform needs at least 3 pairs, got {}", pairs.size()));
  Eigen::Matrix3Xd source(3, pairs.size()), target(3, pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pairs[i].source.allFinite() || !pairs[i].target.allFinite())
      ThrowInputError(what, fmt::format("pairs[{}]", i), "", "non-finite coordinate (NaN or infinity)");
    source.col(i) = pairs[i].source;
    target.col(i) = pairs[i].target;
  }
  const Eigen::Vector3d spread =
      Eigen::JacobiSVD<Eigen::Matrix3Xd>(source.colwise() - source.rowwise().mean()).singularValues();
  if (spread[1] <= 1e-6 * spread[0])
    ThrowInputError(what, "", "pairs",
                    "the landmarks are collinear (or all equal): the rotation is not determined");
  LandmarkAlignment result;
  result.model = with_scale ? LandmarkModel::kSimilarity : LandmarkModel::kRigid;
  result.target_from_source = Eigen::umeyama(source, target, with_scale);
  result.scale = std::cbrt(result.target_from_source.topLeftCorner<3, 3>().determinant());
  double sum = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d moved = (result.target_from_source * pairs[i].source.homogeneous()).head<3>();
    result.residual_m.push_back((moved - pairs[i].target).norm());
    sum += result.residual_m.back() * result.residual_m.back();
  }
  result.rms_m = std::sqrt(sum / pairs.size());
  return result;
}

namespace {

void ToOpenCv(std::span<const PixelPair> pairs, size_t minimum, const char* model, const std::string& what,
              std::vector<cv::Point2d>* a, std::vector<cv::Point2d>* b) {
  if (pairs.size() < minimum)
    ThrowInputError(what, "", "pairs",
                    fmt::format("a {} needs at least {} pairs, got {}", model, minimum, pairs.size()));
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pairs[i].pixel_a.allFinite() || !pairs[i].pixel_b.allFinite())
      ThrowInputError(what, fmt::format("pairs[{}]", i), "", "non-finite coordinate (NaN or infinity)");
    a->emplace_back(pairs[i].pixel_a.x(), pairs[i].pixel_a.y());
    b->emplace_back(pairs[i].pixel_b.x(), pairs[i].pixel_b.y());
  }
}

// Fills matrix, inliers and RMS from OpenCV's output; `error` gives each pair's error under the model.
template <typename Error>
PhotoPairModel Finish(const cv::Mat& matrix, const std::vector<uchar>& mask, std::span<const PixelPair> pairs,
                      const char* model, const std::string& what, Error error) {
  if (matrix.empty() || matrix.rows != 3)
    ThrowInputError(what, "", "pairs",
                    fmt::format("no {} fits the pairs (degenerate or too many outliers)", model));
  PhotoPairModel result;
  cv::cv2eigen(matrix, result.matrix);
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    result.error_px.push_back(error(result.matrix, pairs[i]));
    result.inlier.push_back(i < mask.size() && mask[i] ? 1 : 0);
    if (result.inlier.back()) sum += result.error_px.back() * result.error_px.back(), ++count;
  }
  result.rms_px = count ? std::sqrt(sum / count) : 0;
  return result;
}

}  // namespace

PhotoPairModel EstimateHomography(std::span<const PixelPair> pairs, double threshold_px,
                                  const std::string& what) {
  std::vector<cv::Point2d> a, b;
  ToOpenCv(pairs, 4, "homography", what, &a, &b);
  std::vector<uchar> mask;
  const cv::Mat h = cv::findHomography(a, b, cv::RANSAC, threshold_px, mask, 2000, 0.999);
  PhotoPairModel result =
      Finish(h, mask, pairs, "homography", what, [](const Eigen::Matrix3d& m, const PixelPair& pair) {
        return ((m * pair.pixel_a.homogeneous()).hnormalized() - pair.pixel_b).norm();
      });
  result.model = PhotoModel::kHomography;
  return result;
}

PhotoPairModel EstimateFundamental(std::span<const PixelPair> pairs, double threshold_px,
                                   const std::string& what) {
  std::vector<cv::Point2d> a, b;
  ToOpenCv(pairs, 8, "fundamental matrix", what, &a, &b);
  std::vector<uchar> mask;
  const cv::Mat f = cv::findFundamentalMat(a, b, cv::FM_RANSAC, threshold_px, 0.999, mask);
  PhotoPairModel result =
      Finish(f.rows > 3 ? f.rowRange(0, 3) : f, mask, pairs, "fundamental matrix", what,
             [](const Eigen::Matrix3d& m, const PixelPair& pair) {
               const Eigen::Vector3d line = m * pair.pixel_a.homogeneous();
               return std::abs(line.dot(pair.pixel_b.homogeneous())) / line.head<2>().norm();
             });
  result.model = PhotoModel::kFundamental;
  return result;
}

PhotoPairModel EstimatePhotoModel(std::span<const PixelPair> pairs, const AlignOptions& options,
                                  const std::string& what) {
  Validate(options);
  return options.model == PhotoModel::kFundamental ? EstimateFundamental(pairs, options.threshold_px, what)
                                                   : EstimateHomography(pairs, options.threshold_px, what);
}

}  // namespace lidarshop
