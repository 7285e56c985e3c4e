#include "lidarshop/recolor/auto_resection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/recolor/auto_resection_render.h"
#include "lidarshop/recolor/silhouette_alignment.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using auto_resection_internal::kDegPerRad;
using auto_resection_internal::Median;
using auto_resection_internal::Render;
using auto_resection_internal::SamplesOf;
using auto_resection_internal::Scaled;
using auto_resection_internal::ScanSamples;
using auto_resection_internal::SetPose;
using auto_resection_internal::View;

// A camera whose last round moved it less than this has settled (a supported camera must have).
constexpr double kSettledMoveM = 0.01, kSettledTurnDeg = 0.05;
// The check: a camera is ambiguous when another explains at least kMinCheckInliers and kCheckMargin x as many
// of the unambiguous SIFT pairs (on seeds 18 and 23, wrong by 8 and 30 cm: 74 vs 210, 45 vs 152; right
// cameras: the same count). Rounds start again from that camera at most kMaxRestarts times.
constexpr int kMinCheckInliers = 12;
constexpr double kCheckMargin = 1.5;
constexpr int kMaxRestarts = 2;

struct Features {
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;  // CV_32F, one row per key
};

// SIFT keypoints in a fixed order (position, size, angle), then their descriptors: the same on any thread count.
Features Detect(const cv::Mat& grey, const cv::Mat& mask, int features) {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(features);
  Features out;
  sift->detect(grey, out.keys, mask);
  std::sort(out.keys.begin(), out.keys.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    return std::tie(a.pt.y, a.pt.x, a.size, a.angle, a.response, a.octave) <
           std::tie(b.pt.y, b.pt.x, b.size, b.angle, b.response, b.octave);
  });
  if (!out.keys.empty()) sift->compute(grey, out.keys, out.descriptors);
  return out;
}

cv::Mat ValidMask(const View& view) {
  cv::Mat mask = view.depth < std::numeric_limits<float>::infinity();
  cv::erode(mask, mask, cv::Mat::ones(3, 3, CV_8U));
  return mask;
}

// Working-pixel position (continuous) of an OpenCV keypoint.
Eigen::Vector2d Continuous(const cv::KeyPoint& key) { return {key.pt.x + 0.5, key.pt.y + 0.5}; }

// The world point a view shows at a keypoint: bilinear over the four pixel centres around it when they lie
// on one surface (depths within 2 %), else the nearest pixel's; false when there is none.
bool PointAt(const View& view, const cv::KeyPoint& key, Eigen::Vector3d* point_in_world) {
  const double u = key.pt.x, v = key.pt.y;  // OpenCV: pixel centres at integers
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  const double fx = u - x0, fy = v - y0;
  const Eigen::Vector3d eye = view.camera.center_in_world();
  const auto inside = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < view.depth.cols && y < view.depth.rows;
  };
  if (inside(x0, y0) && inside(x0 + 1, y0 + 1)) {
    float lo = std::numeric_limits<float>::infinity(), hi = 0;
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float z = view.depth.at<float>(y0 + dy, x0 + dx);
        lo = std::min(lo, z), hi = std::max(hi, z);
      }
    if (std::isfinite(hi) && hi < 1.02f * lo) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const cv::Vec3f p = view.point_from_eye.at<cv::Vec3f>(y0 + dy, x0 + dx);
          sum += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * Eigen::Vector3d(p[0], p[1], p[2]);
        }
      *point_in_world = eye + sum;
      return true;
    }
  }
  const int x = static_cast<int>(std::lround(u)), y = static_cast<int>(std::lround(v));
  if (!inside(x, y) || !std::isfinite(view.depth.at<float>(y, x))) return false;
  const cv::Vec3f p = view.point_from_eye.at<cv::Vec3f>(y, x);
  *point_in_world = eye + Eigen::Vector3d(p[0], p[1], p[2]);
  return true;
}

// Search matches: the ratio test over all of the view's features.
std::vector<PixelPointPair> MatchAll(const Features& photo, const Features& view_features, const View& view,
                                     double to_photo_x, double to_photo_y, double ratio) {
  std::vector<PixelPointPair> pairs;
  if (photo.keys.size() < 2 || view_features.keys.size() < 2) return pairs;
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(photo.descriptors, view_features.descriptors, knn, 2);
  for (const std::vector<cv::DMatch>& m : knn) {
    if (m.size() < 2 || m[0].distance >= ratio * m[1].distance) continue;
    Eigen::Vector3d point;
    if (!PointAt(view, view_features.keys[m[0].trainIdx], &point)) continue;
    const Eigen::Vector2d q = Continuous(photo.keys[m[0].queryIdx]);
    pairs.push_back({Eigen::Vector2d(q.x() * to_photo_x, q.y() * to_photo_y), point});
  }
  return pairs;
}

// Round matches: the view is rendered from the camera's estimate, so a photo feature's match lies within
// `radius_px`; the ratio test runs among those. Pairs are made sub-pixel (header, step 3).
std::vector<PixelPointPair> MatchGuided(const Features& photo, const Features& view_features,
                                        const View& view, double to_photo_x, double to_photo_y, double ratio,
                                        double radius_px) {
  std::vector<PixelPointPair> pairs;
  // Buckets of view features by cell of `radius_px` side.
  const double cell = std::max(radius_px, 1.0);
  const int grid_cols = static_cast<int>(view.depth.cols / cell) + 1,
            grid_rows = static_cast<int>(view.depth.rows / cell) + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(grid_cols) * grid_rows);
  for (size_t j = 0; j < view_features.keys.size(); ++j) {
    const cv::Point2f& p = view_features.keys[j].pt;
    const int gx = std::clamp(static_cast<int>(p.x / cell), 0, grid_cols - 1),
              gy = std::clamp(static_cast<int>(p.y / cell), 0, grid_rows - 1);
    buckets[static_cast<size_t>(gy) * grid_cols + gx].push_back(static_cast<int>(j));
  }
  const double radius2 = radius_px * radius_px;
  for (size_t i = 0; i < photo.keys.size(); ++i) {
    const cv::Point2f& p = photo.keys[i].pt;
    const int gx = static_cast<int>(p.x / cell), gy = static_cast<int>(p.y / cell);
    double best = std::numeric_limits<double>::infinity(), second = best;
    int best_j = -1;
    for (int by = gy - 1; by <= gy + 1; ++by) {
      for (int bx = gx - 1; bx <= gx + 1; ++bx) {
        if (bx < 0 || by < 0 || bx >= grid_cols || by >= grid_rows) continue;
        for (int j : buckets[static_cast<size_t>(by) * grid_cols + bx]) {
          const cv::Point2f d = view_features.keys[j].pt - p;
          if (d.x * d.x + d.y * d.y > radius2) continue;
          const double distance = cv::norm(photo.descriptors.row(static_cast<int>(i)),
                                           view_features.descriptors.row(j), cv::NORM_L2);
          if (distance < best) {
            second = best, best = distance, best_j = j;
          } else if (distance < second) {
            second = distance;
          }
        }
      }
    }
    if (best_j < 0 || !(best < ratio * second)) continue;
    const cv::KeyPoint& key = view_features.keys[best_j];
    Eigen::Vector3d point;
    if (!PointAt(view, key, &point)) continue;
    const Eigen::Vector2d q = Continuous(photo.keys[i]);
    pairs.push_back({Eigen::Vector2d(q.x() * to_photo_x, q.y() * to_photo_y), point});
  }
  return pairs;
}

// A found patch's correlation must beat the best one 3 or more pixels away by this much.
constexpr double kMinPeakMargin = 0.1;

// Dense pairs: patches of the rendering (every `step_px`, one surface, textured) found in the photo within
// `search_px` by normalized cross-correlation (gain and offset free), the peak refined to sub-pixel by a
// parabola per axis. The rendering's pixel centre shows a known surface point, so each found patch is a pair.
std::vector<PixelPointPair> MatchPatches(const cv::Mat& photo_grey, const View& view, int patch_px,
                                         int step_px, int search_px, double min_score, double to_photo_x,
                                         double to_photo_y) {
  std::vector<PixelPointPair> pairs;
  const int half = patch_px / 2, reach = half + search_px;
  const Eigen::Vector3d eye = view.camera.center_in_world();
  cv::Mat score;
  for (int y = reach; y + reach < view.grey.rows && y + reach < photo_grey.rows; y += step_px) {
    for (int x = reach; x + reach < view.grey.cols && x + reach < photo_grey.cols; x += step_px) {
      const cv::Rect window(x - half, y - half, 2 * half + 1, 2 * half + 1);
      double depth_lo = 0, depth_hi = 0;
      cv::minMaxLoc(view.depth(window), &depth_lo, &depth_hi);
      if (!std::isfinite(depth_hi) || depth_hi > 1.05 * depth_lo) continue;  // an edge or a hole
      const cv::Mat templ = view.grey(window);
      cv::Scalar mean, deviation;
      cv::meanStdDev(templ, mean, deviation);
      if (deviation[0] < 4) continue;  // no texture: the correlation has no peak
      const cv::Rect region(x - reach, y - reach, 2 * reach + 1, 2 * reach + 1);
      cv::matchTemplate(photo_grey(region), templ, score, cv::TM_CCOEFF_NORMED);
      double best = 0;
      cv::Point at;
      cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
      if (best < min_score || at.x == 0 || at.y == 0 || at.x + 1 == score.cols || at.y + 1 == score.rows)
        continue;
      // A repeating texture (bricks) correlates as well one period away: the peak must stand out.
      const cv::Mat peak_free = score.clone();
      cv::rectangle(peak_free, cv::Rect(at.x - 2, at.y - 2, 5, 5), cv::Scalar(-1), cv::FILLED);
      double second = -1;
      cv::minMaxLoc(peak_free, nullptr, &second);
      if (second > best - kMinPeakMargin) continue;
      const auto peak = [](float left, float centre, float right) {
        const double curvature = left - 2.0 * centre + right;
        return curvature < 0 ? 0.5 * (left - right) / curvature : 0.0;
      };
      const double dx =
          at.x - search_px +
          peak(score.at<float>(at.y, at.x - 1), score.at<float>(at.y, at.x), score.at<float>(at.y, at.x + 1));
      const double dy =
          at.y - search_px +
          peak(score.at<float>(at.y - 1, at.x), score.at<float>(at.y, at.x), score.at<float>(at.y + 1, at.x));
      const cv::Vec3f p = view.point_from_eye.at<cv::Vec3f>(y, x);
      pairs.push_back({Eigen::Vector2d((x + 0.5 + dx) * to_photo_x, (y + 0.5 + dy) * to_photo_y),
                       eye + Eigen::Vector3d(p[0], p[1], p[2])});
    }
  }
  return pairs;
}

struct Pose {
  bool ok = false;
  PinholeCamera camera;
  std::vector<uint8_t> inlier;
  int inliers = 0;
  double rms_px = 0;
};

// OpenCV's K and distortion of a camera (OpenCV puts the centre of pixel (0, 0) at (0, 0)).
cv::Matx33d OpenCvK(const PinholeCamera& c) {
  return cv::Matx33d(c.fx_px, c.skew_px, c.cx_px - 0.5, 0, c.fy_px, c.cy_px - 0.5, 0, 0, 1);
}
cv::Mat OpenCvDistortion(const PinholeCamera& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

void GetPose(const PinholeCamera& camera, cv::Mat* rvec, cv::Mat* tvec) {
  const Eigen::Matrix3d r = camera.world_from_camera.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d t = -r * camera.world_from_camera.topRightCorner<3, 1>();
  cv::Mat rotation;
  cv::eigen2cv(r, rotation);
  cv::Rodrigues(rotation, *rvec);
  *tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
}

// Inliers of `camera` within `threshold_px` and their RMS.
void SelectInliers(std::span<const PixelPointPair> pairs, double threshold_px, Pose* pose) {
  pose->inlier.assign(pairs.size(), 0);
  pose->inliers = 0;
  double sum = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const double error = ReprojectionError(pose->camera, pairs[i]);
    if (error < threshold_px) pose->inlier[i] = 1, ++pose->inliers, sum += error * error;
  }
  pose->rms_px = pose->inliers > 0 ? std::sqrt(sum / pose->inliers) : 0;
}

// Levenberg–Marquardt on the pose over the current inliers, then inliers re-selected; twice.
void RefinePose(std::span<const PixelPointPair> pairs, double threshold_px, Pose* pose) {
  for (int pass = 0; pass < 2 && pose->inliers >= 4; ++pass) {
    std::vector<cv::Point3d> objects;
    std::vector<cv::Point2d> images;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (!pose->inlier[i]) continue;
      objects.emplace_back(pairs[i].point_in_world.x(), pairs[i].point_in_world.y(),
                           pairs[i].point_in_world.z());
      images.emplace_back(pairs[i].pixel_px.x() - 0.5, pairs[i].pixel_px.y() - 0.5);
    }
    cv::Mat rvec, tvec;
    GetPose(pose->camera, &rvec, &tvec);
    cv::solvePnPRefineLM(objects, images, OpenCvK(pose->camera), OpenCvDistortion(pose->camera), rvec, tvec,
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-10));
    SetPose(rvec, tvec, &pose->camera);
    SelectInliers(pairs, threshold_px, pose);
  }
}

// PnP RANSAC (EPnP minimal sets; OpenCV seeds its own RANSAC, theRNG is set for good measure) and
// refinement, pairs in photo pixels with the intrinsics of `intrinsics`.
Pose SolvePose(std::span<const PixelPointPair> pairs, const PinholeCamera& intrinsics, double threshold_px,
               const AutoResectionOptions& options) {
  Pose pose;
  if (pairs.size() < 6) return pose;
  std::vector<cv::Point3d> objects;
  std::vector<cv::Point2d> images;
  for (const PixelPointPair& pair : pairs) {
    objects.emplace_back(pair.point_in_world.x(), pair.point_in_world.y(), pair.point_in_world.z());
    images.emplace_back(pair.pixel_px.x() - 0.5, pair.pixel_px.y() - 0.5);
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  cv::theRNG().state = options.seed;
  bool ok = false;
  try {
    ok = cv::solvePnPRansac(objects, images, OpenCvK(intrinsics), OpenCvDistortion(intrinsics), rvec, tvec,
                            false, options.ransac_iterations, static_cast<float>(threshold_px), 0.9999,
                            inliers, cv::SOLVEPNP_EPNP);
  } catch (const cv::Exception&) {
    ok = false;  // degenerate minimal sets everywhere: no pose
  }
  if (!ok || inliers.size() < 6) return pose;
  pose.camera = intrinsics;
  SetPose(rvec, tvec, &pose.camera);
  SelectInliers(pairs, threshold_px, &pose);
  RefinePose(pairs, threshold_px, &pose);
  pose.ok = pose.inliers >= 6;
  return pose;
}

// Unknown intrinsics: golden-section search of the focal length (square pixels) within ±15 % that gives the
// inliers the lowest RMS, the pose refined for each; then the pose refined and the inliers re-selected.
void RefineFocal(std::span<const PixelPointPair> pairs, double threshold_px, Pose* pose) {
  const std::vector<uint8_t> inlier = pose->inlier;
  const auto rms_with = [&](double focal_px, PinholeCamera* out) {
    Pose trial = *pose;
    trial.camera.fx_px = trial.camera.fy_px = focal_px;
    std::vector<cv::Point3d> objects;
    std::vector<cv::Point2d> images;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (!inlier[i]) continue;
      objects.emplace_back(pairs[i].point_in_world.x(), pairs[i].point_in_world.y(),
                           pairs[i].point_in_world.z());
      images.emplace_back(pairs[i].pixel_px.x() - 0.5, pairs[i].pixel_px.y() - 0.5);
    }
    cv::Mat rvec, tvec;
    GetPose(trial.camera, &rvec, &tvec);
    cv::solvePnPRefineLM(objects, images, OpenCvK(trial.camera), OpenCvDistortion(trial.camera), rvec, tvec);
    SetPose(rvec, tvec, &trial.camera);
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (!inlier[i]) continue;
      const double e = std::min(ReprojectionError(trial.camera, pairs[i]), 3 * threshold_px);
      sum += e * e, ++n;
    }
    if (out) *out = trial.camera;
    return n ? sum / n : 0.0;
  };
  const double phi = (std::sqrt(5.0) - 1) / 2;
  double lo = std::log(pose->camera.fx_px / 1.15), hi = std::log(pose->camera.fx_px * 1.15);
  double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
  double fa = rms_with(std::exp(a), nullptr), fb = rms_with(std::exp(b), nullptr);
  for (int i = 0; i < 30; ++i) {
    if (fa < fb) {
      hi = b, b = a, fb = fa, a = hi - phi * (hi - lo), fa = rms_with(std::exp(a), nullptr);
    } else {
      lo = a, a = b, fa = fb, b = lo + phi * (hi - lo), fb = rms_with(std::exp(b), nullptr);
    }
  }
  rms_with(std::exp(0.5 * (lo + hi)), &pose->camera);
  SelectInliers(pairs, threshold_px, pose);
  RefinePose(pairs, threshold_px, pose);
}

// The intrinsics of a horizontal field of view for a photo of this size.
PinholeCamera IntrinsicsOfFov(int width_px, int height_px, double fov_deg) {
  PinholeCamera camera;
  camera.width_px = width_px, camera.height_px = height_px;
  camera.fx_px = camera.fy_px = 0.5 * width_px / std::tan(0.5 * fov_deg / kDegPerRad);
  camera.cx_px = 0.5 * width_px, camera.cy_px = 0.5 * height_px;
  return camera;
}

double RotationAngleDeg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const Eigen::Matrix3d r = a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>();
  return std::acos(std::clamp((r.trace() - 1) / 2, -1.0, 1.0)) * kDegPerRad;
}

// The working images of one set of intrinsics.
struct Working {
  PinholeCamera intrinsics;  // photo pixels
  int width_px = 0, height_px = 0;
  double to_photo_x = 1, to_photo_y = 1;  // photo pixels per working pixel
  Features photo;
  cv::Mat grey;  // CV_8U, the photo at the working size
};

Working MakeWorking(const cv::Mat& photo_grey, const PinholeCamera& intrinsics, const ScanSamples& samples,
                    const AutoResectionOptions& options) {
  Working w;
  w.intrinsics = intrinsics;
  const double scale =
      std::min(1.0, options.pixels_per_cell / (samples.cell_angle_rad * std::max(intrinsics.fx_px, 1.0)));
  w.width_px = std::max(16, static_cast<int>(std::lround(photo_grey.cols * scale)));
  w.height_px = std::max(16, static_cast<int>(std::lround(photo_grey.rows * scale)));
  w.to_photo_x = static_cast<double>(photo_grey.cols) / w.width_px;
  w.to_photo_y = static_cast<double>(photo_grey.rows) / w.height_px;
  cv::Mat small;
  if (w.width_px == photo_grey.cols && w.height_px == photo_grey.rows) {
    small = photo_grey;
  } else {
    cv::resize(photo_grey, small, cv::Size(w.width_px, w.height_px), 0, 0, cv::INTER_AREA);
  }
  w.photo = Detect(small, cv::Mat(), options.features);
  w.grey = small;
  return w;
}

}  // namespace

void AutoResectionOptions::Check() const {
  if (fov_candidates_deg.empty()) throw OptionsError("fov_candidates_deg: give at least one field of view");
  for (double fov : fov_candidates_deg)
    if (!(fov > 1 && fov < 179))
      throw OptionsError(fmt::format("fov_candidates_deg: {} is not in (1, 179)", fov));
  if (view_elevations_deg.empty()) throw OptionsError("view_elevations_deg: give at least one elevation");
  for (double e : view_elevations_deg)
    if (!(std::abs(e) <= 80))
      throw OptionsError(fmt::format("view_elevations_deg: {} is not in [-80, 80]", e));
  if (view_azimuths < 1 || view_azimuths > 72) throw OptionsError("view_azimuths must be in [1, 72]");
  if (!(pixels_per_cell > 0.05 && pixels_per_cell <= 8))
    throw OptionsError("pixels_per_cell must be in (0.05, 8]");
  if (features < 50) throw OptionsError("features must be at least 50");
  if (!(ratio > 0 && ratio <= 1)) throw OptionsError("ratio must be in (0, 1]");
  if (rounds < 0) throw OptionsError("rounds must be >= 0");
  if (!(guided_radius_px > 0)) throw OptionsError("guided_radius_px must be > 0");
  if (!(ransac_threshold_px > 0)) throw OptionsError("ransac_threshold_px must be > 0");
  if (ransac_iterations < 1) throw OptionsError("ransac_iterations must be >= 1");
  if (search_candidates < 1) throw OptionsError("search_candidates must be >= 1");
  if (min_inliers < 6) throw OptionsError("min_inliers must be at least 6");
  if (!(min_inlier_share >= 0 && min_inlier_share <= 1))
    throw OptionsError("min_inlier_share must be in [0, 1]");
  if (!(max_rms_px > 0)) throw OptionsError("max_rms_px must be > 0");
  if (patch_px < 0 || patch_px > 63 || (patch_px > 0 && patch_px % 2 == 0))
    throw OptionsError("patch_px must be 0 (off) or odd in [3, 63]");
  if (patch_step_px < 1) throw OptionsError("patch_step_px must be >= 1");
  if (!(min_patch_score >= -1 && min_patch_score <= 1))
    throw OptionsError("min_patch_score must be in [-1, 1]");
}

AutoResectionSummary SummarizeAutoResection(const AutoResectionResult& result) {
  AutoResectionSummary summary;
  summary.method = result.method;
  summary.inliers = result.inliers;
  summary.pairs = static_cast<int64_t>(result.pairs.size());
  summary.inlier_share = result.inlier_share;
  summary.rms_px = result.rms_px;
  summary.rms_work_px = result.rms_work_px;
  summary.work_scale = result.work_scale;
  summary.rounds = result.rounds;
  summary.search_view = result.search_view;
  summary.search_inliers = result.search_inliers;
  if (result.search_fov_deg > 0) summary.search_fov_deg = result.search_fov_deg;
  summary.check_pairs = result.check_pairs;
  summary.check_agree = result.check_agree;
  summary.check_alt_inliers = result.check_alt_inliers;
  if (result.method == "silhouettes") {
    summary.silhouette_edge_share = result.silhouette_edge_share;
    summary.silhouette_mutual_information = result.silhouette_mutual_information;
  }
  summary.focal_px = {result.camera.fx_px, result.camera.fy_px};
  const Eigen::Vector3d center = result.camera.center_in_world();
  summary.camera_center = {center.x(), center.y(), center.z()};
  summary.warnings = result.warnings;
  return summary;
}

std::string AutoResectionResult::Summary() const {
  return fmt::format(
      "automatic resection ({}): {} of {} pairs inliers ({:.0f} %), RMS {:.2f} px ({:.2f} working px), {} "
      "round(s), "
      "camera at ({:.3f}, {:.3f}, {:.3f}) m, focal {:.1f} px",
      method, inliers, pairs.size(), 100 * inlier_share, rms_px, rms_work_px, rounds,
      camera.center_in_world().x(), camera.center_in_world().y(), camera.center_in_world().z(), camera.fx_px);
}

namespace {

// Steps 1-5 (features); throws InputError when no camera is supported.
AutoResectionResult FeatureResection(const Scan& scan, const cv::Mat& photo,
                                     const AutoResectionOptions& options,
                                     const std::optional<PinholeCamera>& intrinsics,
                                     const std::optional<Eigen::Matrix4d>& rough_world_from_camera,
                                     const std::string& what) {
  if (photo.empty() || (photo.type() != CV_8UC3 && photo.type() != CV_8UC1))
    ThrowInputError(what, "", "", "automatic resection needs an 8-bit RGB or grey photo");
  cv::Mat photo_grey;
  if (photo.channels() == 3) {
    cv::cvtColor(photo, photo_grey, cv::COLOR_RGB2GRAY);
  } else {
    photo_grey = photo;
  }
  const ScanSamples samples = SamplesOf(scan, what);
  if (static_cast<int>(samples.point_in_world.size()) < options.min_inliers)
    ThrowInputError(what, "", "scan",
                    fmt::format("the scan has {} returns: too few for an automatic resection",
                                samples.point_in_world.size()));

  // The intrinsics to try, each with its working images.
  std::vector<Working> workings;
  if (intrinsics) {
    intrinsics->Check(what + " intrinsics");
    PinholeCamera known = *intrinsics;
    if (known.width_px != photo.cols || known.height_px != photo.rows)
      known = Scaled(known, photo.cols, photo.rows);
    known.world_from_camera.setIdentity();
    workings.push_back(MakeWorking(photo_grey, known, samples, options));
  } else {
    for (double fov : options.fov_candidates_deg)
      workings.push_back(
          MakeWorking(photo_grey, IntrinsicsOfFov(photo.cols, photo.rows, fov), samples, options));
  }

  // Search: views from the scanner centre (or the rough pose); every view's PnP camera is a candidate, the
  // one with the most inliers first.
  struct Candidate {
    Pose pose;
    size_t working = 0;
    int view = -1;
  };
  std::vector<Candidate> candidates;
  int most_pairs = 0;
  const Eigen::Matrix3d scanner_rotation = scan.world_from_scanner.topLeftCorner<3, 3>();
  for (size_t w = 0; w < workings.size(); ++w) {
    const Working& working = workings[w];
    const double threshold_px = 3 * options.ransac_threshold_px * working.to_photo_x;
    std::vector<Eigen::Matrix4d> poses;
    if (rough_world_from_camera) {
      poses.push_back(*rough_world_from_camera);
    } else {
      for (double elevation_deg : options.view_elevations_deg) {
        for (int a = 0; a < options.view_azimuths; ++a) {
          const double azimuth = 2 * M_PI * a / options.view_azimuths, elevation = elevation_deg / kDegPerRad;
          const Eigen::Vector3d look =
              scanner_rotation * Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth),
                                                 std::cos(elevation) * std::cos(azimuth),
                                                 std::sin(elevation));
          poses.push_back(
              CameraLookingAt(samples.scanner_in_world, samples.scanner_in_world + look, 64, 48, 60)
                  .world_from_camera);
        }
      }
    }
    for (size_t v = 0; v < poses.size(); ++v) {
      // The photo's focal length on a canvas 1.5 x as large (the rough pose: the photo's own frame).
      const double canvas = rough_world_from_camera ? 1.0 : 1.5;
      PinholeCamera camera = Scaled(working.intrinsics, working.width_px, working.height_px);
      camera.width_px = static_cast<int>(std::lround(canvas * working.width_px));
      camera.height_px = static_cast<int>(std::lround(canvas * working.height_px));
      camera.cx_px += 0.5 * (camera.width_px - working.width_px);
      camera.cy_px += 0.5 * (camera.height_px - working.height_px);
      camera.k1 = camera.k2 = camera.k3 = camera.p1 = camera.p2 = 0;
      camera.world_from_camera = poses[v];
      const View view = Render(samples, camera);
      const Features view_features = Detect(view.grey, ValidMask(view), options.features);
      const std::vector<PixelPointPair> pairs =
          MatchAll(working.photo, view_features, view, working.to_photo_x, working.to_photo_y, options.ratio);
      most_pairs = std::max(most_pairs, static_cast<int>(pairs.size()));
      const Pose pose = SolvePose(pairs, working.intrinsics, threshold_px, options);
      if (pose.ok) candidates.push_back({pose, w, rough_world_from_camera ? -1 : static_cast<int>(v)});
    }
  }
  if (candidates.empty())
    ThrowInputError(
        what, "", "features",
        fmt::format("no rendering of the scan matches the photo: at most {} matches in a view, and "
                    "no pose explains 6 of them",
                    most_pairs));
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.pose.inliers > b.pose.inliers; });

  // Rounds from one candidate: render from the estimate, match near the same place, solve again.
  std::optional<Pose> last_alt;  // run_rounds' check: the camera the unambiguous SIFT pairs alone give
  const auto run_rounds = [&](const Candidate& start) {
    last_alt.reset();
    AutoResectionResult out;
    out.trace = fmt::format("search view {} ({} inliers):", start.view, start.pose.inliers);
    const Working& working = workings[start.working];
    const double threshold_px = options.ransac_threshold_px * working.to_photo_x;
    PinholeCamera camera = start.pose.camera;
    Pose pose = start.pose;
    std::vector<PixelPointPair> pairs;
    double radius_px = options.guided_radius_px;
    bool dense_rounds = false;
    for (int round = 0; round < options.rounds; ++round) {
      PinholeCamera work = Scaled(camera, working.width_px, working.height_px);
      const View view = Render(samples, work);
      const Features view_features = Detect(view.grey, ValidMask(view), options.features);
      // The first round matches anywhere (the search's camera may be degrees off: its views were rendered
      // from the scanner centre); later ones near the same place.
      std::vector<PixelPointPair> round_pairs =
          round == 0 ? MatchAll(working.photo, view_features, view, working.to_photo_x, working.to_photo_y,
                                options.ratio)
                     : MatchGuided(working.photo, view_features, view, working.to_photo_x, working.to_photo_y,
                                   options.ratio, radius_px);
      // Patches only once SIFT alone has settled (the camera moved less than 1 cm and 0.05° in a round):
      // from a camera a few pixels off, a patch of a repeating texture (bricks) finds the next brick as
      // well, and the whole wall shifted by one brick is a consistent, wrong answer.
      if (dense_rounds) {
        const std::vector<PixelPointPair> dense =
            MatchPatches(working.grey, view, options.patch_px, options.patch_step_px,
                         static_cast<int>(std::ceil(radius_px)), options.min_patch_score, working.to_photo_x,
                         working.to_photo_y);
        round_pairs.insert(round_pairs.end(), dense.begin(), dense.end());
      }
      Pose next = SolvePose(round_pairs, camera, threshold_px, options);
      if (!next.ok) {
        out.trace += fmt::format(" round {}: {} pairs, no pose;", round + 1, round_pairs.size());
        break;
      }
      if (!intrinsics) RefineFocal(round_pairs, threshold_px, &next);
      out.rounds = round + 1;
      const double moved_m = (next.camera.center_in_world() - camera.center_in_world()).norm(),
                   turned_deg = RotationAngleDeg(next.camera.world_from_camera, camera.world_from_camera);
      out.last_move_m = moved_m, out.last_turn_deg = turned_deg;
      out.trace += fmt::format(" round {}: {} of {} pairs, moved {:.1f} cm {:.2f}°;", round + 1, next.inliers,
                               round_pairs.size(), 100 * moved_m, turned_deg);
      camera = next.camera;
      pose = next;
      pairs = std::move(round_pairs);
      // The next search radius follows the estimate's accuracy (never wider than asked).
      radius_px = std::clamp(6 * pose.rms_px / working.to_photo_x, 3.0, options.guided_radius_px);
      if (!dense_rounds && options.patch_px > 0) {
        dense_rounds = moved_m < kSettledMoveM && turned_deg < kSettledTurnDeg;
        continue;
      }
      if (moved_m < 1e-3 && turned_deg < 5e-3) break;
    }
    if (out.rounds > 0) {
      // The independent check (header, step 5): SIFT alone, ratio-tested over the whole rendering.
      const View view = Render(samples, Scaled(camera, working.width_px, working.height_px));
      const Features view_features = Detect(view.grey, ValidMask(view), options.features);
      const std::vector<PixelPointPair> check =
          MatchAll(working.photo, view_features, view, working.to_photo_x, working.to_photo_y, options.ratio);
      std::vector<double> errors_work_px;
      for (const PixelPointPair& pair : check)
        errors_work_px.push_back(ReprojectionError(camera, pair) / working.to_photo_x);
      out.check_pairs = static_cast<int>(check.size());
      out.check_agree =
          static_cast<int>(std::count_if(errors_work_px.begin(), errors_work_px.end(),
                                         [&](double e) { return e < options.ransac_threshold_px; }));
      out.check_median_work_px = Median(errors_work_px);
      const Pose alt = SolvePose(check, camera, threshold_px, options);
      if (alt.ok) {
        out.check_alt_inliers = alt.inliers;
        out.check_alt_move_m = (alt.camera.center_in_world() - camera.center_in_world()).norm();
        last_alt = alt;
      }
      out.trace += fmt::format(" alt {} moved {:.1f} cm;", out.check_alt_inliers, 100 * out.check_alt_move_m);
      out.trace += fmt::format(" check: {} of {} SIFT pairs agree, median {:.1f} px", out.check_agree,
                               out.check_pairs, out.check_median_work_px);
    }
    out.camera = camera;
    out.pairs = std::move(pairs);
    out.inlier = pose.inlier;
    out.inliers = out.rounds > 0 ? pose.inliers : 0;
    out.inlier_share = out.pairs.empty() ? 0 : static_cast<double>(pose.inliers) / out.pairs.size();
    out.rms_px = pose.rms_px;
    out.work_scale = 1 / working.to_photo_x;
    out.rms_work_px = pose.rms_px / working.to_photo_x;
    out.search_view = start.view;
    out.search_inliers = start.pose.inliers;
    out.search_fov_deg = intrinsics ? 0 : options.fov_candidates_deg[start.working];
    return out;
  };
  // The check (header, step 5): the SIFT pairs ratio-tested over the whole rendering, which a repeating
  // texture cannot make agree with a camera a period over, are better explained by another camera.
  const auto ambiguous = [&](const AutoResectionResult& r) {
    return r.check_alt_inliers >= kMinCheckInliers && r.check_alt_inliers > kCheckMargin * r.check_agree;
  };
  const auto supported = [&](const AutoResectionResult& r) {
    // A camera still moving in its last round has not settled on what the photo shows (a repeating texture
    // pulls it one period over at a time): not supported either.
    return r.rounds > 0 && r.inliers >= options.min_inliers && r.inlier_share >= options.min_inlier_share &&
           r.rms_work_px <= options.max_rms_px && r.last_move_m < kSettledMoveM &&
           r.last_turn_deg < kSettledTurnDeg && !ambiguous(r);
  };
  // The best candidate first; the next ones only while none gives a supported camera.
  AutoResectionResult result;
  std::string traces;
  if (static_cast<int>(candidates.size()) > options.search_candidates)
    candidates.resize(options.search_candidates);
  int restarts = 0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    AutoResectionResult r = run_rounds(candidates[i]);
    traces += (i ? " | " : "") + r.trace;
    // An ambiguous camera: the rounds start again from the unambiguous pairs' camera, next.
    if (ambiguous(r) && last_alt && restarts < kMaxRestarts) {
      ++restarts;
      candidates.insert(candidates.begin() + static_cast<std::ptrdiff_t>(i) + 1,
                        Candidate{*last_alt, candidates[i].working, candidates[i].view});
    }
    const bool better = i == 0 || (supported(r) && !supported(result)) ||
                        (supported(r) == supported(result) && r.inliers > result.inliers);
    if (better) result = std::move(r);
    if (supported(result)) break;
  }
  if (result.rounds == 0)
    ThrowInputError(what, "", "features",
                    fmt::format("the search found a camera ({} inliers) but no rendering from it matches the "
                                "photo again: the camera is not supported (tried: {})",
                                candidates[0].pose.inliers, traces));
  if (ambiguous(result))
    ThrowInputError(
        what, "", "features",
        fmt::format(
            "no supported camera: ambiguous: of the {} SIFT pairs ratio-tested over the whole photo, {} "
            "agree with the camera and {} with another one {:.1f} cm away (a repeating texture such as "
            "bricks can hold the camera one period over); tried: {}",
            result.check_pairs, result.check_agree, result.check_alt_inliers, 100 * result.check_alt_move_m,
            traces));
  if (!supported(result))
    ThrowInputError(
        what, "", "features",
        fmt::format(
            "no supported camera: {} of {} matches agree ({:.0f} %; at least {} and {:.0f} % needed), "
            "RMS {:.2f} working px (at most {:.2f}); the photo may not show the scan, or from too far "
            "(give a rough pose); tried: {}",
            result.inliers, result.pairs.size(), 100 * result.inlier_share, options.min_inliers,
            100 * options.min_inlier_share, result.rms_work_px, options.max_rms_px, traces));
  return result;
}

}  // namespace

AutoResectionResult AutoResection(const Scan& scan, const cv::Mat& photo, const AutoResectionOptions& options,
                                  const std::optional<PinholeCamera>& intrinsics,
                                  const std::optional<Eigen::Matrix4d>& rough_world_from_camera,
                                  const std::string& what) {
  options.Check();
  if (photo.empty() || (photo.type() != CV_8UC3 && photo.type() != CV_8UC1))
    ThrowInputError(what, "", "", "automatic resection needs an 8-bit RGB or grey photo");
  try {
    return FeatureResection(scan, photo, options, intrinsics, rough_world_from_camera, what);
  } catch (const InputError& feature_error) {
    // Step 6 (header): only from a rough pose with known intrinsics; the synthetic evaluation's searches
    // from the scanner centre never come here.
    if (!options.silhouettes || !rough_world_from_camera || !intrinsics) throw;
    PinholeCamera start = *intrinsics;
    if (start.width_px != photo.cols || start.height_px != photo.rows)
      start = Scaled(start, photo.cols, photo.rows);
    start.world_from_camera = *rough_world_from_camera;
    cv::Mat photo_grey;
    if (photo.channels() == 3) {
      cv::cvtColor(photo, photo_grey, cv::COLOR_RGB2GRAY);
    } else {
      photo_grey = photo;
    }
    SilhouetteAlignmentOptions silhouette_options;
    silhouette_options.min_pairs = options.min_inliers;
    const SilhouetteAlignment aligned = AlignSilhouettes(scan, photo_grey, start, silhouette_options, what);
    if (!aligned.ok)
      ThrowInputError(
          what, "", "features",
          fmt::format(
              "{} -- and the silhouette alignment from the rough pose is not supported either: {} "
              "(at least {:.0f} % of the model edges on a photo edge at 384 px wide and {:.0f} % at 768 px, "
              "mutual information {:.2f} and {} pairs needed)",
              feature_error.what(), aligned.trace, 100 * silhouette_options.min_edge_share,
              100 * silhouette_options.min_fine_edge_share, silhouette_options.min_mutual_information,
              silhouette_options.min_pairs));
    AutoResectionResult result;
    result.method = "silhouettes";
    result.camera = aligned.camera;
    result.pairs = aligned.pairs;
    result.inlier.assign(aligned.pairs.size(), 1);
    result.inliers = aligned.inliers;
    result.inlier_share = aligned.pairs.empty() ? 0 : 1;
    result.rms_px = aligned.rms_px;
    result.work_scale = aligned.work_scale;
    result.rms_work_px = aligned.rms_px * aligned.work_scale;
    result.silhouette_edge_share = aligned.edge_share;
    result.silhouette_mutual_information = aligned.mutual_information;
    result.trace = aligned.trace;
    result.warnings.push_back(fmt::format(
        "{}: no rendering of the scan shares enough features with the photo; the camera comes from the "
        "silhouette alignment (outlines and intensity, from the rough pose): {:.0f} % of the scan's outlines "
        "lie "
        "on the photo's edges. It is coarser than a feature camera (pumpA: about 19 px from its hand-picked "
        "pairs, whose own RMS is 6.3 px): check the recolouring's edges",
        what, 100 * aligned.edge_share));
    return result;
  }
}

}  // namespace lidarshop
