#include "lidarshop/recolor/resection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

void ResectionOptions::Check() const {
  Validate(*this);
  CheckOption(width_px > 0 && height_px > 0,
              fmt::format("resection: the photo size must be > 0, got {} x {}", width_px, height_px));
}

std::string ResectionResult::Summary() const {
  return fmt::format(
      "{} of {} pairs are inliers, RMS reprojection error {:.3f} px (DLT {:.3f} px), {} RANSAC sets",
      num_inliers, inlier.size(), rms_px, dlt_rms_px, ransac_iterations);
}

ResectionSummary SummarizeResection(const ResectionResult& result) {
  ResectionSummary summary;
  summary.inliers = result.num_inliers;
  summary.pairs = static_cast<int64_t>(result.inlier.size());
  summary.rms_px = result.rms_px;
  summary.dlt_rms_px = result.dlt_rms_px;
  summary.ransac_sets = result.ransac_iterations;
  summary.focal_px = {result.camera.fx_px, result.camera.fy_px};
  summary.principal_point_px = {result.camera.cx_px, result.camera.cy_px};
  summary.k1 = result.camera.k1;
  const Eigen::Vector3d center = result.camera.center_in_world();
  summary.camera_center = {center.x(), center.y(), center.z()};
  for (size_t i = 0; i < result.inlier.size(); ++i)
    summary.per_pair.push_back({result.reprojection_error_px[i], result.inlier[i] != 0});
  summary.warnings = result.warnings;
  return summary;
}

namespace {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

std::vector<std::string> ResectionWarnings(const ResectionResult& result) {
  std::vector<std::string> warnings;
  if (result.rms_px > kResectionRmsWarningPx) {
    warnings.push_back(fmt::format(
        "the camera's inliers reproject with an RMS of {:.1f} px (more than {:g} px): a pair may be wrong or "
        "the lens distorts more than the model; a recolouring with it paints objects' edges onto their "
        "neighbours (check the pairs' error_px)",
        result.rms_px, kResectionRmsWarningPx));
  }
  return warnings;
}

// Similarity taking `points` (as columns) to zero mean and mean distance sqrt(dimension).
template <int D>
Eigen::Matrix<double, D + 1, D + 1> NormalizingTransform(
    const std::vector<Eigen::Matrix<double, D, 1>>& points) {
  Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double distance = 0;
  for (const auto& p : points) distance += (p - mean).norm();
  distance /= static_cast<double>(points.size());
  const double scale = distance > 0 ? std::sqrt(static_cast<double>(D)) / distance : 1.0;
  Eigen::Matrix<double, D + 1, D + 1> t = Eigen::Matrix<double, D + 1, D + 1>::Identity();
  t.template topLeftCorner<D, D>() *= scale;
  t.template topRightCorner<D, 1>() = -scale * mean;
  return t;
}

// Singular values of centred rows, largest first.
template <int D>
Eigen::Matrix<double, D, 1> Spread(const std::vector<Eigen::Matrix<double, D, 1>>& points) {
  Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix<double, Eigen::Dynamic, D> centred(points.size(), D);
  for (size_t i = 0; i < points.size(); ++i) centred.row(i) = (points[i] - mean).transpose();
  return Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, D>>(centred).singularValues();
}

// Reprojection error with a projection matrix (no distortion).
double ProjectionError(const Matrix34d& p, const PixelPointPair& pair) {
  const Eigen::Vector3d x = p * pair.point_in_world.homogeneous();
  if (std::abs(x.z()) < 1e-300) return std::numeric_limits<double>::infinity();
  return (x.hnormalized() - pair.pixel_px).norm();
}

// The camera parameters LM works on: fx fy cx cy skew k1 k2 k3 p1 p2 | rotation (angle-axis) | translation,
// the pose as camera_from_world.
constexpr int kNumParameters = 16;
using Parameters = Eigen::Matrix<double, kNumParameters, 1>;

Parameters ToParameters(const PinholeCamera& c) {
  const Eigen::Matrix3d rotation = c.world_from_camera.topLeftCorner<3, 3>().transpose();
  const Eigen::AngleAxisd angle_axis(rotation);
  const Eigen::Vector3d r = angle_axis.angle() * angle_axis.axis();
  const Eigen::Vector3d t = -rotation * c.center_in_world();
  Parameters x;
  x << c.fx_px, c.fy_px, c.cx_px, c.cy_px, c.skew_px, c.k1, c.k2, c.k3, c.p1, c.p2, r, t;
  return x;
}

PinholeCamera FromParameters(const Parameters& x, int width_px, int height_px) {
  PinholeCamera c;
  c.width_px = width_px;
  c.height_px = height_px;
  c.fx_px = x[0], c.fy_px = x[1], c.cx_px = x[2], c.cy_px = x[3], c.skew_px = x[4];
  c.k1 = x[5], c.k2 = x[6], c.k3 = x[7], c.p1 = x[8], c.p2 = x[9];
  const Eigen::Vector3d r = x.segment<3>(10);
  const double angle = r.norm();
  const Eigen::Matrix3d rotation =
      angle > 0 ? Eigen::AngleAxisd(angle, r / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  c.world_from_camera.setIdentity();
  c.world_from_camera.topLeftCorner<3, 3>() = rotation.transpose();
  c.world_from_camera.topRightCorner<3, 1>() = -rotation.transpose() * x.segment<3>(13);
  return c;
}

// Residuals (du, dv per pair) over the free parameters; fy follows fx when `tie_fy`.
struct ReprojectionFunctor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  std::vector<PixelPointPair> pairs;
  std::vector<int> free;  // indices into Parameters
  Parameters fixed;
  bool tie_fy = true;
  int width_px = 0, height_px = 0;

  int inputs() const { return static_cast<int>(free.size()); }
  int values() const { return static_cast<int>(2 * pairs.size()); }
  Parameters Full(const Eigen::VectorXd& x) const {
    Parameters full = fixed;
    for (size_t i = 0; i < free.size(); ++i) full[free[i]] = x[i];
    if (tie_fy) full[1] = full[0];
    return full;
  }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& residual) const {
    const PinholeCamera camera = FromParameters(Full(x), width_px, height_px);
    for (size_t i = 0; i < pairs.size(); ++i) {
      Eigen::Vector2d pixel;
      if (!ProjectWorldPoint(camera, pairs[i].point_in_world, &pixel))
        pixel = pairs[i].pixel_px.array() + 1e6;
      residual.segment<2>(2 * i) = pixel - pairs[i].pixel_px;
    }
    return 0;
  }
};

// Levenberg–Marquardt over the pose and the intrinsics the inlier count supports: the focal length(s)
// always; the principal point from `min_inliers_for_principal_point` inliers (else the photo's centre);
// distortion from `min_inliers_for_distortion`.
std::optional<PinholeCamera> Refine(const PinholeCamera& start, const std::vector<PixelPointPair>& pairs,
                                    const ResectionOptions& options) {
  const int count = static_cast<int>(pairs.size());
  const bool free_principal_point = count >= options.min_inliers_for_principal_point;
  ReprojectionFunctor functor;
  functor.pairs = pairs;
  functor.fixed = ToParameters(start);
  functor.tie_fy = options.square_pixels;
  functor.width_px = options.width_px;
  functor.height_px = options.height_px;
  if (options.square_pixels) functor.fixed[0] = functor.fixed[1] = 0.5 * (start.fx_px + start.fy_px);
  if (!options.refine_skew || !free_principal_point) functor.fixed[4] = 0;
  functor.free = {0};
  if (free_principal_point) {
    functor.free.insert(functor.free.end(), {2, 3});
  } else {
    functor.fixed[2] = 0.5 * options.width_px;
    functor.fixed[3] = 0.5 * options.height_px;
  }
  if (!options.square_pixels) functor.free.push_back(1);
  if (options.refine_skew && free_principal_point) functor.free.push_back(4);
  if (count >= options.min_inliers_for_distortion) {
    for (int k = 0; k < options.radial_coefficients; ++k) functor.free.push_back(5 + k);
    if (options.refine_tangential) functor.free.insert(functor.free.end(), {8, 9});
  }
  for (int i = 10; i < kNumParameters; ++i) functor.free.push_back(i);
  if (functor.values() < functor.inputs()) return std::nullopt;
  Eigen::VectorXd x(functor.free.size());
  for (size_t i = 0; i < functor.free.size(); ++i) x[i] = functor.fixed[functor.free[i]];
  Eigen::NumericalDiff<ReprojectionFunctor> numeric(functor);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<ReprojectionFunctor>> solver(numeric);
  solver.parameters.maxfev = 4000;
  solver.parameters.xtol = 1e-12;
  solver.parameters.ftol = 1e-12;
  solver.minimize(x);
  return FromParameters(functor.Full(x), options.width_px, options.height_px);
}

// The camera of a minimal set under the intrinsics prior (square pixels, principal point at the photo's centre,
// no skew): for sets whose DLT is no plausible camera (near-planar sets leave the DLT's intrinsics undetermined;
// the prior's focal length and pose stay determined). Poses from EPnP for a few fields of view, each refined by
// Levenberg–Marquardt over the focal length and the pose; the one that fits the set best.
std::optional<PinholeCamera> PriorCamera(const std::vector<PixelPointPair>& sample,
                                         const ResectionOptions& options) {
  ResectionOptions prior = options;
  prior.min_inliers_for_principal_point = std::numeric_limits<int>::max();
  prior.min_inliers_for_distortion = std::numeric_limits<int>::max();
  prior.square_pixels = true;
  std::vector<cv::Point3d> object_points;
  std::vector<cv::Point2d> image_points;
  for (const PixelPointPair& pair : sample) {
    object_points.emplace_back(pair.point_in_world.x(), pair.point_in_world.y(), pair.point_in_world.z());
    image_points.emplace_back(pair.pixel_px.x() - 0.5, pair.pixel_px.y() - 0.5);
  }
  std::optional<PinholeCamera> best;
  double best_sum = std::numeric_limits<double>::infinity();
  for (const double fov_deg : {30.0, 50.0, 70.0, 90.0}) {
    PinholeCamera camera;
    camera.width_px = options.width_px;
    camera.height_px = options.height_px;
    camera.fx_px = camera.fy_px = 0.5 * options.width_px / std::tan(0.5 * fov_deg * M_PI / 180.0);
    camera.cx_px = 0.5 * options.width_px;
    camera.cy_px = 0.5 * options.height_px;
    const cv::Matx33d k(camera.fx_px, 0, camera.cx_px - 0.5, 0, camera.fy_px, camera.cy_px - 0.5, 0, 0, 1);
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(object_points, image_points, k, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_EPNP))
      continue;
    cv::Matx33d rotation;
    cv::Rodrigues(rvec, rotation);
    Eigen::Matrix3d r;
    cv::cv2eigen(cv::Mat(rotation), r);
    const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    if (!r.allFinite() || !t.allFinite()) continue;
    camera.world_from_camera.setIdentity();
    camera.world_from_camera.topLeftCorner<3, 3>() = r.transpose();
    camera.world_from_camera.topRightCorner<3, 1>() = -r.transpose() * t;
    const std::optional<PinholeCamera> refined = Refine(camera, sample, prior);
    if (!refined || !(refined->fx_px > 0)) continue;
    double sum = 0;
    for (const PixelPointPair& pair : sample) sum += std::pow(ReprojectionError(*refined, pair), 2);
    if (sum < best_sum) {
      best_sum = sum;
      best = refined;
    }
  }
  return best;
}

double RmsOfInliers(const PinholeCamera& camera, std::span<const PixelPointPair> pairs,
                    const std::vector<uint8_t>& inlier) {
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!inlier[i]) continue;
    const double e = ReprojectionError(camera, pairs[i]);
    sum += e * e;
    ++count;
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

std::vector<PixelPointPair> Select(std::span<const PixelPointPair> pairs, const std::vector<uint8_t>& keep) {
  std::vector<PixelPointPair> out;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (keep[i]) out.push_back(pairs[i]);
  }
  return out;
}

}  // namespace

Eigen::Matrix<double, 3, 4> NormalizedDlt(std::span<const PixelPointPair> pairs) {
  LIDARSHOP_CHECK(pairs.size() >= 6);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  for (const PixelPointPair& pair : pairs) {
    pixels.push_back(pair.pixel_px);
    points.push_back(pair.point_in_world);
  }
  const Eigen::Matrix3d t2 = NormalizingTransform<2>(pixels);
  const Eigen::Matrix4d t3 = NormalizingTransform<3>(points);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * pairs.size(), 12);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector2d x = (t2 * pixels[i].homogeneous()).head<2>();
    const Eigen::RowVector4d big_x = (t3 * points[i].homogeneous()).transpose();
    // Eq. 3.6.
    a.block<1, 4>(2 * i, 0) = big_x;
    a.block<1, 4>(2 * i, 8) = -x.x() * big_x;
    a.block<1, 4>(2 * i + 1, 4) = big_x;
    a.block<1, 4>(2 * i + 1, 8) = -x.y() * big_x;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd p = svd.matrixV().col(11);
  Matrix34d normalized;
  normalized << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(), p.segment<4>(8).transpose();
  Matrix34d projection = t2.inverse() * normalized * t3;
  return projection / projection.norm();
}

ProjectionFactors DecomposeProjection(const Eigen::Matrix<double, 3, 4>& projection) {
  Matrix34d p = projection;
  if (p.leftCols<3>().determinant() < 0) p = -p;
  Eigen::Matrix3d flip;
  flip << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  // RQ from QR: flip * M = (Q R')^T gives M = (flip R'^T flip)(flip Q^T).
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * p.leftCols<3>()).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d r_upper = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d k = flip * r_upper.transpose() * flip;
  Eigen::Matrix3d rotation = flip * q.transpose();
  const Eigen::Vector3d signs(k(0, 0) < 0 ? -1 : 1, k(1, 1) < 0 ? -1 : 1, k(2, 2) < 0 ? -1 : 1);
  k = k * signs.asDiagonal();
  rotation = signs.asDiagonal() * rotation;
  ProjectionFactors factors;
  factors.camera_from_world_translation = k.inverse() * p.col(3);
  factors.K = k / k(2, 2);
  factors.camera_from_world_rotation = rotation;
  return factors;
}

PinholeCamera CameraFromProjection(const Eigen::Matrix<double, 3, 4>& projection, int width_px,
                                   int height_px) {
  const ProjectionFactors f = DecomposeProjection(projection);
  PinholeCamera camera;
  camera.width_px = width_px;
  camera.height_px = height_px;
  camera.fx_px = f.K(0, 0);
  camera.fy_px = f.K(1, 1);
  camera.cx_px = f.K(0, 2);
  camera.cy_px = f.K(1, 2);
  camera.skew_px = f.K(0, 1);
  camera.world_from_camera.topLeftCorner<3, 3>() = f.camera_from_world_rotation.transpose();
  camera.world_from_camera.topRightCorner<3, 1>() =
      -f.camera_from_world_rotation.transpose() * f.camera_from_world_translation;
  return camera;
}

double ReprojectionError(const PinholeCamera& camera, const PixelPointPair& pair) {
  Eigen::Vector2d pixel;
  if (!ProjectWorldPoint(camera, pair.point_in_world, &pixel)) return std::numeric_limits<double>::infinity();
  return (pixel - pair.pixel_px).norm();
}

void CheckResectionInput(std::span<const PixelPointPair> pairs, double degenerate_ratio,
                         const std::string& what, bool points_may_be_planar) {
  const size_t needed = points_may_be_planar ? 4 : 6;
  if (pairs.size() < needed)
    ThrowInputError(what, "", "pairs",
                    fmt::format("resectioning needs at least {} pairs, got {}", needed, pairs.size()));
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pairs[i].pixel_px.allFinite() || !pairs[i].point_in_world.allFinite())
      ThrowInputError(what, fmt::format("pairs[{}]", i), "", "non-finite coordinate (NaN or infinity)");
    pixels.push_back(pairs[i].pixel_px);
    points.push_back(pairs[i].point_in_world);
  }
  const Eigen::Vector2d pixel_spread = Spread<2>(pixels);
  if (pixel_spread[1] <= degenerate_ratio * pixel_spread[0])
    ThrowInputError(what, "", "pairs", "the pixels are collinear (or all equal): they cannot fix a camera");
  const Eigen::Vector3d point_spread = Spread<3>(points);
  if (point_spread[1] <= degenerate_ratio * point_spread[0])
    ThrowInputError(what, "", "pairs", "the points are collinear (or all equal): they cannot fix a camera");
  if (!points_may_be_planar && point_spread[2] <= degenerate_ratio * point_spread[0])
    ThrowInputError(what, "", "pairs",
                    "all points lie on one plane: the DLT cannot recover the intrinsics from a plane; give "
                    "known intrinsics (--intrinsics CAM.json) or points off the plane");
}

ResectionResult Resection(std::span<const PixelPointPair> pairs, const ResectionOptions& options,
                          const std::string& what) {
  options.Check();
  CheckResectionInput(pairs, options.degenerate_ratio, what);
  const int n = static_cast<int>(pairs.size());
  const double t2 = options.ransac_threshold_px * options.ransac_threshold_px;
  ResectionResult result;

  // MSAC: every pair costs its squared error, capped at the threshold's square; `inliers` gets the pairs
  // within the threshold.
  const auto score_camera = [&](const auto& error_of, std::vector<uint8_t>* inliers) {
    double score = 0;
    inliers->assign(n, 0);
    for (int i = 0; i < n; ++i) {
      const double e = error_of(pairs[i]);
      (*inliers)[i] = e * e < t2;
      score += std::min(e * e, t2);
    }
    return score;
  };
  const auto count_of = [](const std::vector<uint8_t>& inliers) {
    return static_cast<int>(std::count(inliers.begin(), inliers.end(), 1));
  };
  // Local optimization (LO-RANSAC): the DLT on a set's inliers, Levenberg–Marquardt with the intrinsics the
  // inlier count supports (Refine), inliers re-selected with the refined camera, twice; scored after.
  struct Candidate {
    PinholeCamera camera;
    std::vector<uint8_t> inliers;
    double score = std::numeric_limits<double>::infinity();
  };
  const auto optimize = [&](const Candidate& start) {
    std::vector<uint8_t> inliers = start.inliers;
    Candidate out;
    out.camera =
        CameraFromProjection(NormalizedDlt(Select(pairs, inliers)), options.width_px, options.height_px);
    out.score = score_camera([&](const PixelPointPair& pair) { return ReprojectionError(out.camera, pair); },
                             &out.inliers);
    if (!(out.score < start.score)) out = start;  // e.g. near-planar inliers: the DLT is no camera
    if (!options.refine) return out;
    // With refinement, candidates are refined cameras only: a set whose refinement fails is no candidate.
    out.score = std::numeric_limits<double>::infinity();
    for (int round = 0; round < 2 && count_of(inliers) >= 6; ++round) {
      const std::optional<PinholeCamera> refined = Refine(out.camera, Select(pairs, inliers), options);
      if (!refined || !(refined->fx_px > 0 && refined->fy_px > 0)) break;
      std::vector<uint8_t> next;
      const double score =
          score_camera([&](const PixelPointPair& pair) { return ReprojectionError(*refined, pair); }, &next);
      if (!std::isfinite(score) || count_of(next) < 6) break;
      // The first refinement is taken even when the DLT scored lower: candidates are compared under the
      // model the inlier count supports, not with the DLT's free intrinsics.
      if (!(score < out.score) && round > 0) break;
      out = {*refined, next, score};
      if (next == inliers) break;
      inliers = next;
    }
    return out;
  };

  // RANSAC over minimal sets of 6 (serial, seeded).
  std::mt19937_64 rng(options.seed);
  std::vector<int> order(n);
  Candidate best;
  // The best minimal set so far (most inliers, then lowest MSAC score). With local optimization every set
  // with as many inliers as the refined best is refitted (once per distinct inlier set): with few pairs a
  // wrong set can hold the best minimal score, and only its refitted rivals show it.
  int best_set_count = -1;
  double best_set_score = std::numeric_limits<double>::infinity();
  std::vector<std::vector<uint8_t>> optimized;  // inlier sets already locally optimized
  int iterations_needed = options.ransac_iterations;
  std::vector<PixelPointPair> sample(6);
  std::vector<Eigen::Vector3d> sample_points(6);
  for (int iteration = 0; iteration < iterations_needed; ++iteration) {
    std::iota(order.begin(), order.end(), 0);
    for (int i = 0; i < 6; ++i) {
      std::swap(order[i], order[i + static_cast<int>(rng() % static_cast<uint64_t>(n - i))]);
      sample[i] = pairs[order[i]];
      sample_points[i] = sample[i].point_in_world;
    }
    result.ransac_iterations = iteration + 1;
    const Eigen::Vector3d spread = Spread<3>(sample_points);
    if (spread[2] <= options.degenerate_ratio * spread[0]) continue;  // a planar set: no camera
    Matrix34d p = NormalizedDlt(sample);
    if (p.leftCols<3>().determinant() < 0) p = -p;  // then (P X)_z > 0 in front of the camera
    std::optional<PinholeCamera> prior_camera;      // set when the DLT is no plausible camera
    if (options.square_pixels) {
      // A minimal set fits nearly any 6 pairs; a camera far from square pixels and zero skew is a wrong one —
      // or a near-planar set whose intrinsics the DLT cannot fix: with local optimization, such a set gets
      // the camera of the intrinsics prior instead.
      const Eigen::Matrix3d k = DecomposeProjection(p).K;
      if (std::abs(k(0, 0) / k(1, 1) - 1) > options.max_aspect_deviation ||
          std::abs(k(0, 1)) > options.max_aspect_deviation * k(0, 0)) {
        if (!options.local_optimization) continue;
        prior_camera = PriorCamera(sample, options);
        if (!prior_camera) continue;
      }
    }
    std::vector<uint8_t> inliers;
    const double score =
        prior_camera
            ? score_camera([&](const PixelPointPair& pair) { return ReprojectionError(*prior_camera, pair); },
                           &inliers)
            : score_camera(
                  [&](const PixelPointPair& pair) {
                    const bool in_front = (p.row(2) * pair.point_in_world.homogeneous()) > 0;
                    return in_front ? ProjectionError(p, pair) : std::numeric_limits<double>::infinity();
                  },
                  &inliers);
    const int count = count_of(inliers);
    // With local optimization the bar is the refined best's inlier count (a wrong minimal set may collect
    // more pairs than any right one before refinement) or its MSAC score: a camera bent to absorb an outlier
    // keeps one pair more than the right one, all of them loosely (with 10 pairs: 9 pairs at 1-3.5 px against
    // 8 at 0.5 px), and only the score tells them apart.
    if (count < 6) continue;
    if (options.local_optimization ? count < count_of(best.inliers) && !(score < best.score)
                                   : count < best_set_count)
      continue;
    const bool better_set = count > best_set_count || (count == best_set_count && score < best_set_score);
    if (better_set) {
      best_set_count = count;
      best_set_score = score;
    }
    Candidate candidate{
        prior_camera ? *prior_camera : CameraFromProjection(p, options.width_px, options.height_px), inliers,
        score};
    if (options.local_optimization) {
      if (std::find(optimized.begin(), optimized.end(), inliers) != optimized.end()) continue;
      optimized.push_back(inliers);
      candidate = optimize(candidate);
      // Compared after refinement.
      if (count_of(candidate.inliers) < 6 || !(candidate.score < best.score)) continue;
    } else if (!better_set) {
      continue;
    }
    best = std::move(candidate);
    const double w = static_cast<double>(std::max(count, count_of(best.inliers))) / n;
    const double miss = 1.0 - std::pow(w, 6);
    if (miss <= 0) {
      iterations_needed = std::min(iterations_needed, std::max(iteration + 1, options.ransac_min_iterations));
    } else if (miss < 1) {
      const double needed = std::log(1.0 - options.ransac_confidence) / std::log(miss);
      iterations_needed = static_cast<int>(std::min<double>(
          options.ransac_iterations, std::max<double>(options.ransac_min_iterations, std::ceil(needed))));
    }
  }
  // Swap search: an outlier can also be absorbed by trading it for a right pair (the camera bends to fit the
  // outlier exactly and pushes one right pair just past the threshold: as many inliers, as tight; with 10 pairs
  // both cameras fit 8 pairs at 0.5 px, and a pair left out alone leaves 7 too weak to bring the right one
  // back). Each inlier is traded in turn for each of the (at most 3) nearest pairs just outside the threshold
  // (below 3 thresholds) and the set refitted from the refined best (`optimize`, inliers re-selected); the
  // lowest MSAC score wins; repeated until no trade lowers it. At most 3 x inliers refits per round.
  if (options.local_optimization && options.refine && count_of(best.inliers) >= 6) {
    for (int round = 0, improved = 1; improved && round < n; ++round) {
      improved = 0;
      std::vector<std::pair<double, int>> outside;  // (error, pair) of the pairs just outside the threshold
      for (int j = 0; j < n; ++j) {
        const double e = ReprojectionError(best.camera, pairs[j]);
        if (!best.inliers[j] && e < 3 * options.ransac_threshold_px) outside.emplace_back(e, j);
      }
      std::sort(outside.begin(), outside.end());
      outside.resize(std::min<size_t>(outside.size(), 3));
      Candidate next = best;
      for (const auto& [error, j] : outside) {
        for (int i = 0; i < n; ++i) {
          if (!best.inliers[i]) continue;
          Candidate start = best;
          start.inliers[i] = 0;
          start.inliers[j] = 1;
          Candidate traded = optimize(start);
          if (count_of(traded.inliers) >= 6 && traded.score < next.score)
            next = std::move(traded), improved = 1;
        }
      }
      if (improved) best = std::move(next);
    }
  }
  if (count_of(best.inliers) < 6)
    ThrowInputError(what, "", "pairs",
                    fmt::format("no 6 pairs agree on a camera within {} px (best set: {} inliers)",
                                options.ransac_threshold_px, std::max(count_of(best.inliers), 0)));

  // The DLT on the inliers (reported), then LM, re-selection and LM again from the best camera.
  result.projection = NormalizedDlt(Select(pairs, best.inliers));
  const PinholeCamera dlt_camera =
      CameraFromProjection(result.projection, options.width_px, options.height_px);
  result.dlt_rms_px = RmsOfInliers(dlt_camera, pairs, best.inliers);
  result.camera = options.local_optimization ? best.camera : dlt_camera;
  result.inlier = best.inliers;
  if (options.refine) {
    for (int round = 0; round < 2; ++round) {
      const std::optional<PinholeCamera> refined =
          Refine(result.camera, Select(pairs, result.inlier), options);
      if (!refined) break;  // too few residuals for the free parameters
      // Keep the refinement only when it is a camera that explains its inliers within the
      // threshold (LM can run off from a poor start). Its RMS may exceed the DLT's: fixed skew and
      // square pixels fit the noise less.
      if (!(refined->fx_px > 0 && refined->fy_px > 0) ||
          !(RmsOfInliers(*refined, pairs, result.inlier) < options.ransac_threshold_px))
        break;
      result.camera = *refined;
      std::vector<uint8_t> inliers(n, 0);
      for (int i = 0; i < n; ++i)
        inliers[i] = ReprojectionError(result.camera, pairs[i]) < options.ransac_threshold_px;
      if (std::count(inliers.begin(), inliers.end(), 1) < 6 || inliers == result.inlier) break;
      result.inlier = inliers;
    }
  }
  for (int i = 0; i < n; ++i)
    result.reprojection_error_px.push_back(ReprojectionError(result.camera, pairs[i]));
  result.num_inliers = static_cast<int>(std::count(result.inlier.begin(), result.inlier.end(), 1));
  result.rms_px = RmsOfInliers(result.camera, pairs, result.inlier);
  result.warnings = ResectionWarnings(result);
  return result;
}

ResectionResult ResectWithIntrinsics(std::span<const PixelPointPair> pairs, const PinholeCamera& intrinsics,
                                     const ResectionOptions& options, const std::string& what) {
  options.Check();
  CheckResectionInput(pairs, options.degenerate_ratio, what, /*points_may_be_planar=*/true);
  std::vector<cv::Point3d> object_points;
  std::vector<cv::Point2d> image_points;
  for (const PixelPointPair& pair : pairs) {
    object_points.emplace_back(pair.point_in_world.x(), pair.point_in_world.y(), pair.point_in_world.z());
    // OpenCV puts the centre of pixel (0, 0) at (0, 0).
    image_points.emplace_back(pair.pixel_px.x() - 0.5, pair.pixel_px.y() - 0.5);
  }
  cv::Matx33d k(intrinsics.fx_px, intrinsics.skew_px, intrinsics.cx_px - 0.5, 0, intrinsics.fy_px,
                intrinsics.cy_px - 0.5, 0, 0, 1);
  const cv::Mat distortion =
      (cv::Mat_<double>(1, 5) << intrinsics.k1, intrinsics.k2, intrinsics.p1, intrinsics.p2, intrinsics.k3);
  cv::Mat rvec, tvec;
  std::vector<int> inlier_indices;
  cv::theRNG().state = options.seed;
  const bool ok =
      cv::solvePnPRansac(object_points, image_points, k, distortion, rvec, tvec, false,
                         options.ransac_iterations, static_cast<float>(options.ransac_threshold_px),
                         options.ransac_confidence, inlier_indices, cv::SOLVEPNP_EPNP);
  if (!ok || inlier_indices.size() < 4)
    ThrowInputError(what, "", "pairs", "solvePnPRansac found no pose consistent with the known intrinsics");
  std::vector<cv::Point3d> inlier_objects;
  std::vector<cv::Point2d> inlier_images;
  for (int i : inlier_indices) {
    inlier_objects.push_back(object_points[i]);
    inlier_images.push_back(image_points[i]);
  }
  if (options.refine) cv::solvePnPRefineLM(inlier_objects, inlier_images, k, distortion, rvec, tvec);
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d r;
  cv::cv2eigen(cv::Mat(rotation), r);
  Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  ResectionResult result;
  result.camera = intrinsics;
  result.camera.width_px = options.width_px;
  result.camera.height_px = options.height_px;
  result.camera.world_from_camera.setIdentity();
  result.camera.world_from_camera.topLeftCorner<3, 3>() = r.transpose();
  result.camera.world_from_camera.topRightCorner<3, 1>() = -r.transpose() * t;
  result.projection.leftCols<3>() = result.camera.K() * r;
  result.projection.col(3) = result.camera.K() * t;
  result.inlier.assign(pairs.size(), 0);
  for (int i : inlier_indices) result.inlier[i] = 1;
  for (const PixelPointPair& pair : pairs)
    result.reprojection_error_px.push_back(ReprojectionError(result.camera, pair));
  result.num_inliers = static_cast<int>(inlier_indices.size());
  result.rms_px = result.dlt_rms_px = RmsOfInliers(result.camera, pairs, result.inlier);
  result.warnings = ResectionWarnings(result);
  return result;
}

}  // namespace lidarshop
