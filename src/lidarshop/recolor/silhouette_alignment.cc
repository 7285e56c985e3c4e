#include "lidarshop/recolor/silhouette_alignment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/recolor/auto_resection_render.h"

namespace lidarshop {
namespace {

using auto_resection_internal::Render;
using auto_resection_internal::SamplesOf;
using auto_resection_internal::Scaled;
using auto_resection_internal::ScanSamples;
using auto_resection_internal::SetPose;
using auto_resection_internal::Shade;
using auto_resection_internal::View;

constexpr double kRadPerDeg = M_PI / 180;
constexpr int kBins = 8;         // edge orientations (modulo 180°): 22.5° each, a model edge looks in 3
constexpr int kHistogram = 32;   // mutual information's bins per image
constexpr double kNearPx = 1.5;  // an edge "lies on" a photo edge this near (step 4)

PinholeCamera AtWidth(const PinholeCamera& camera, int width_px) {
  const int w = std::min(width_px, camera.width_px);
  return Scaled(camera, w,
                std::max(1, static_cast<int>(std::lround(camera.height_px * double(w) / camera.width_px))));
}

cv::Mat Reduced(const cv::Mat& grey, const PinholeCamera& work) {
  if (grey.cols == work.width_px && grey.rows == work.height_px) return grey;
  cv::Mat out;
  cv::resize(grey, out, cv::Size(work.width_px, work.height_px), 0, 0, cv::INTER_AREA);
  return out;
}

// Mutual information (nats) of two grey images over `mask` (or of pairs of values added one by one).
struct JointHistogram {
  std::array<double, kHistogram * kHistogram> joint{};
  double n = 0;
  void Add(uint8_t a, uint8_t b) {
    joint[(a * kHistogram / 256) * kHistogram + b * kHistogram / 256] += 1, n += 1;
  }
  double MutualInformation() const {
    if (n < 1) return 0;
    std::array<double, kHistogram> pa{}, pb{};
    for (int i = 0; i < kHistogram; ++i)
      for (int j = 0; j < kHistogram; ++j)
        pa[i] += joint[i * kHistogram + j], pb[j] += joint[i * kHistogram + j];
    double mi = 0;
    for (int i = 0; i < kHistogram; ++i)
      for (int j = 0; j < kHistogram; ++j) {
        const double h = joint[i * kHistogram + j];
        if (h > 0) mi += h / n * std::log(h * n / (pa[i] * pb[j]));
      }
    return mi;
  }
};

double MutualInformationOf(const ScanSamples& samples, const cv::Mat& photo_small,
                           const PinholeCamera& camera) {
  const View view = Render(samples, Scaled(camera, photo_small.cols, photo_small.rows));
  JointHistogram h;
  for (int y = 0; y < photo_small.rows; ++y)
    for (int x = 0; x < photo_small.cols; ++x)
      if (std::isfinite(view.depth.at<float>(y, x)))
        h.Add(view.grey.at<uint8_t>(y, x), photo_small.at<uint8_t>(y, x));
  return h.MutualInformation();
}

Eigen::Matrix3d CameraTurn(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// Step 1.
double SearchRotation(const ScanSamples& samples, const cv::Mat& photo_small, PinholeCamera* camera) {
  const PinholeCamera work = Scaled(*camera, photo_small.cols, photo_small.rows);
  PinholeCamera canvas = work;
  canvas.width_px *= 2, canvas.height_px *= 2;
  canvas.cx_px += 0.5 * work.width_px, canvas.cy_px += 0.5 * work.height_px;
  const View view = Render(samples, canvas);
  double best = -1;
  Eigen::Matrix3d best_turn = Eigen::Matrix3d::Identity();
  const double step = 0.5 * kRadPerDeg;
  for (int i = -16; i <= 16; ++i)
    for (int j = -16; j <= 16; ++j)
      for (int k = -3; k <= 3; ++k) {
        const Eigen::Matrix3d turn = CameraTurn(i * step, j * step, 2 * k * step);
        JointHistogram h;
        for (int y = 0; y < photo_small.rows; ++y)
          for (int x = 0; x < photo_small.cols; ++x) {
            const Eigen::Vector3d ray = turn * Eigen::Vector3d((x + 0.5 - work.cx_px) / work.fx_px,
                                                               (y + 0.5 - work.cy_px) / work.fy_px, 1);
            if (ray.z() <= 0) continue;
            const int u = static_cast<int>(std::floor(canvas.fx_px * ray.x() / ray.z() + canvas.cx_px)),
                      v = static_cast<int>(std::floor(canvas.fy_px * ray.y() / ray.z() + canvas.cy_px));
            if (u < 0 || v < 0 || u >= canvas.width_px || v >= canvas.height_px) continue;
            if (!std::isfinite(view.depth.at<float>(v, u))) continue;
            h.Add(view.grey.at<uint8_t>(v, u), photo_small.at<uint8_t>(y, x));
          }
        const double mi = h.MutualInformation();
        if (mi > best) best = mi, best_turn = turn;
      }
  camera->world_from_camera.topLeftCorner<3, 3>() =
      camera->world_from_camera.topLeftCorner<3, 3>() * best_turn;
  return best;
}

// Step 2.
double LocalSearch(const ScanSamples& samples, const cv::Mat& photo_small, double step_m, double step_deg,
                   PinholeCamera* camera) {
  double current = MutualInformationOf(samples, photo_small, *camera);
  double step_rad = step_deg * kRadPerDeg;
  for (int level = 0; level < 3; ++level, step_m /= 2, step_rad /= 2) {
    for (bool improved = true; improved;) {
      improved = false;
      for (int dof = 0; dof < 6; ++dof)
        for (int sign = -1; sign <= 1; sign += 2) {
          PinholeCamera trial = *camera;
          Eigen::Vector3d axis = Eigen::Vector3d::Zero();
          axis[dof % 3] = 1;
          const Eigen::Matrix3d rotation = trial.world_from_camera.topLeftCorner<3, 3>();
          if (dof < 3) {
            trial.world_from_camera.topRightCorner<3, 1>() += rotation * (sign * step_m * axis);
          } else {
            trial.world_from_camera.topLeftCorner<3, 3>() =
                rotation * Eigen::AngleAxisd(sign * step_rad, axis).toRotationMatrix();
          }
          const double mi = MutualInformationOf(samples, photo_small, trial);
          if (mi > current) current = mi, *camera = trial, improved = true;
        }
    }
  }
  return current;
}

// Photo edges per orientation bin: distance to the nearest and where it is.
struct PhotoEdges {
  std::array<cv::Mat, kBins> distance;              // CV_32F, working px
  std::array<cv::Mat, kBins> label;                 // CV_32S
  std::array<std::vector<cv::Point>, kBins> where;  // label -> pixel
  cv::Mat normal_rad;                               // CV_32F, the gradient's direction
};

int BinOf(double angle_rad) {
  double a = std::fmod(angle_rad, M_PI);
  if (a < 0) a += M_PI;
  return std::min(kBins - 1, static_cast<int>(a / M_PI * kBins));
}

PhotoEdges EdgesOf(const cv::Mat& small) {
  PhotoEdges e;
  cv::Mat smooth, gx, gy, edges;
  cv::GaussianBlur(small, smooth, cv::Size(0, 0), 1.0);
  cv::Sobel(smooth, gx, CV_32F, 1, 0);
  cv::Sobel(smooth, gy, CV_32F, 0, 1);
  cv::Canny(smooth, edges, 30, 90, 3, true);
  cv::phase(gx, gy, e.normal_rad);
  std::array<cv::Mat, kBins> not_edge;
  for (cv::Mat& m : not_edge) m = cv::Mat(small.size(), CV_8U, cv::Scalar(255));
  for (int y = 0; y < small.rows; ++y)
    for (int x = 0; x < small.cols; ++x) {
      if (!edges.at<uint8_t>(y, x)) continue;
      const int b = BinOf(e.normal_rad.at<float>(y, x));
      for (int d = -1; d <= 1; ++d) not_edge[(b + d + kBins) % kBins].at<uint8_t>(y, x) = 0;
    }
  for (int b = 0; b < kBins; ++b) {
    cv::distanceTransform(not_edge[b], e.distance[b], e.label[b], cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);
    for (int y = 0; y < small.rows; ++y)
      for (int x = 0; x < small.cols; ++x) {
        if (not_edge[b].at<uint8_t>(y, x)) continue;
        const size_t l = static_cast<size_t>(e.label[b].at<int32_t>(y, x));
        if (e.where[b].size() <= l) e.where[b].resize(l + 1, cv::Point(-1, -1));
        e.where[b][l] = cv::Point(x, y);
      }
  }
  return e;
}

// Per sample: 255 when its cell is an occluding contour seen from the scanner (some neighbour has no return
// or lies farther by the mesh's depth-edge ratio), not on the grid's border; else 0. Rendered, a pixel shows
// a non-zero value within a cell of such a contour.
std::vector<float> ContourShades(const Scan& scan, const ScanSamples& samples) {
  std::vector<float> shade(samples.point_in_world.size(), 0.f);
  const float ratio = static_cast<float>(auto_resection_internal::kMaxRangeRatio);
  for (int r = 1; r + 1 < scan.rows; ++r)
    for (int c = 1; c + 1 < scan.cols; ++c) {
      const int i = samples.index.at<int32_t>(r, c);
      if (i < 0) continue;
      bool contour = false;
      for (int dr = -1; dr <= 1 && !contour; ++dr)
        for (int dc = -1; dc <= 1 && !contour; ++dc) {
          const int j = samples.index.at<int32_t>(r + dr, c + dc);
          contour = j < 0 || samples.range_m[j] > ratio * samples.range_m[i];
        }
      shade[i] = contour ? 255.f : 0.f;
    }
  return shade;
}

struct ModelEdge {
  Eigen::Vector3d point_in_world;
  double normal_rad = 0;  // in the image, towards what lies behind
};

std::vector<ModelEdge> ModelEdgesOf(const ScanSamples& samples, const ScanSamples& contours,
                                    const PinholeCamera& work) {
  const View view = Render(samples, work);
  const View contour = Render(contours, work);
  const Eigen::Vector3d eye = work.center_in_world();
  std::vector<ModelEdge> out;
  for (int y = 1; y + 1 < view.depth.rows; ++y)
    for (int x = 1; x + 1 < view.depth.cols; ++x) {
      const float z = view.depth.at<float>(y, x);
      if (!std::isfinite(z) || contour.grey.at<uint8_t>(y, x) == 0) continue;
      double nx = 0, ny = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (!(view.depth.at<float>(y + dy, x + dx) < 1.1f * z)) nx += dx, ny += dy;  // farther, or nothing
      if (nx == 0 && ny == 0) continue;
      const cv::Vec3f p = view.point_from_eye.at<cv::Vec3f>(y, x);
      out.push_back({eye + Eigen::Vector3d(p[0], p[1], p[2]), std::atan2(ny, nx)});
    }
  return out;
}

bool Project(const PinholeCamera& camera, const Eigen::Vector3d& point_in_world, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d in_camera = camera.world_from_camera.topLeftCorner<3, 3>().transpose() *
                                    (point_in_world - camera.center_in_world());
  return in_camera.z() > 0.05 && ProjectCameraPoint(camera, in_camera, pixel);
}

// Share of model edges within kNearPx of a photo edge of their orientation.
double EdgeShare(const std::vector<ModelEdge>& model, const PhotoEdges& edges, const PinholeCamera& work) {
  int near = 0;
  for (const ModelEdge& m : model) {
    Eigen::Vector2d pixel;
    if (!Project(work, m.point_in_world, &pixel)) continue;
    const int x = static_cast<int>(std::floor(pixel.x())), y = static_cast<int>(std::floor(pixel.y()));
    const cv::Mat& d = edges.distance[BinOf(m.normal_rad)];
    if (x >= 0 && y >= 0 && x < d.cols && y < d.rows && d.at<float>(y, x) <= kNearPx) ++near;
  }
  return model.empty() ? 0 : static_cast<double>(near) / model.size();
}

// One iteration of step 3 at `work`'s size: pairs, then LM on the pose (in photo pixels).
struct EdgeRound {
  std::vector<PixelPointPair> pairs;
  double rms_work_px = 0;
};
EdgeRound IterateEdges(const std::vector<ModelEdge>& model, const PhotoEdges& edges, double radius_px,
                       const PinholeCamera& work, PinholeCamera* camera) {
  EdgeRound round;
  const double to_photo = static_cast<double>(camera->width_px) / work.width_px;
  for (const ModelEdge& m : model) {
    Eigen::Vector2d pixel;
    if (!Project(work, m.point_in_world, &pixel)) continue;
    const int x = static_cast<int>(std::floor(pixel.x())), y = static_cast<int>(std::floor(pixel.y()));
    const int b = BinOf(m.normal_rad);
    if (x < 0 || y < 0 || x >= edges.distance[b].cols || y >= edges.distance[b].rows) continue;
    if (edges.distance[b].at<float>(y, x) > radius_px) continue;
    const size_t label = static_cast<size_t>(edges.label[b].at<int32_t>(y, x));
    if (label >= edges.where[b].size() || edges.where[b][label].x < 0) continue;
    const cv::Point q = edges.where[b][label];
    // Point-to-line: the model edge moved across the photo edge's line only, not along it.
    const double a = edges.normal_rad.at<float>(q.y, q.x);
    const Eigen::Vector2d normal(std::cos(a), std::sin(a));
    const Eigen::Vector2d target = pixel + normal * normal.dot(Eigen::Vector2d(q.x + 0.5, q.y + 0.5) - pixel);
    round.pairs.push_back({target * to_photo, m.point_in_world});
  }
  if (round.pairs.size() < 6) return round;
  std::vector<cv::Point3d> objects;
  std::vector<cv::Point2d> images;
  for (const PixelPointPair& p : round.pairs) {
    objects.emplace_back(p.point_in_world.x(), p.point_in_world.y(), p.point_in_world.z());
    images.emplace_back(p.pixel_px.x() - 0.5, p.pixel_px.y() - 0.5);
  }
  const Eigen::Matrix3d r = camera->world_from_camera.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d t = -r * camera->world_from_camera.topRightCorner<3, 1>();
  cv::Mat rotation, rvec;
  cv::eigen2cv(r, rotation);
  cv::Rodrigues(rotation, rvec);
  cv::Mat tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
  const cv::Matx33d k(camera->fx_px, camera->skew_px, camera->cx_px - 0.5, 0, camera->fy_px,
                      camera->cy_px - 0.5, 0, 0, 1);
  const cv::Mat distortion =
      (cv::Mat_<double>(1, 5) << camera->k1, camera->k2, camera->p1, camera->p2, camera->k3);
  cv::solvePnPRefineLM(objects, images, k, distortion, rvec, tvec);
  SetPose(rvec, tvec, camera);
  double sum = 0;
  for (const PixelPointPair& p : round.pairs) {
    const double e = ReprojectionError(*camera, p) / to_photo;
    sum += e * e;
  }
  round.rms_work_px = std::sqrt(sum / round.pairs.size());
  return round;
}

}  // namespace

SilhouetteAlignment AlignSilhouettes(const Scan& scan, const cv::Mat& photo_grey, const PinholeCamera& start,
                                     const SilhouetteAlignmentOptions& options, const std::string& what) {
  SilhouetteAlignment out;
  const ScanSamples intensity = SamplesOf(scan, what, Shade::kIntensityElseColor);
  ScanSamples contours = intensity;
  contours.grey = ContourShades(scan, intensity);
  PinholeCamera camera = start;
  // Steps 1 and 2: mutual information of the scan's intensity and the photo.
  const cv::Mat photo_192 = Reduced(photo_grey, AtWidth(start, 192));
  const double mi_rotation = SearchRotation(intensity, photo_192, &camera);
  LocalSearch(intensity, photo_192, 0.2, 1.0, &camera);
  const cv::Mat photo_384 = Reduced(photo_grey, AtWidth(start, 384));
  LocalSearch(intensity, photo_384, 0.05, 0.25, &camera);
  out.trace = fmt::format("rotation search MI {:.3f};", mi_rotation);
  // Step 3: silhouettes.
  EdgeRound last;
  PinholeCamera last_work;
  for (const int width : {384, 768, 1536}) {
    const PinholeCamera size = AtWidth(start, width);
    const PhotoEdges edges = EdgesOf(Reduced(photo_grey, size));
    for (const double radius_px : {8.0, 4.0, 2.0}) {
      for (int iteration = 0; iteration < 8; ++iteration) {
        const PinholeCamera work = Scaled(camera, size.width_px, size.height_px);
        const std::vector<ModelEdge> model = ModelEdgesOf(intensity, contours, work);
        const Eigen::Vector3d before = camera.center_in_world();
        EdgeRound round = IterateEdges(model, edges, radius_px, work, &camera);
        if (round.pairs.size() < 6) break;
        last = std::move(round);
        last_work = work;
        if ((camera.center_in_world() - before).norm() < 0.002) break;
      }
    }
    {
      const PinholeCamera work = Scaled(camera, size.width_px, size.height_px);
      const double share = EdgeShare(ModelEdgesOf(intensity, contours, work), edges, work);
      if (width == 384) out.edge_share = share;
      if (width == 768) out.fine_edge_share = share;
      out.trace += fmt::format(" share at {} px {:.3f};", size.width_px, share);
    }
    if (size.width_px == start.width_px) break;
  }
  out.mutual_information = MutualInformationOf(intensity, photo_192, camera);
  out.camera = camera;
  out.pairs = std::move(last.pairs);
  out.inliers = static_cast<int>(out.pairs.size());
  out.work_scale = static_cast<double>(last_work.width_px) / start.width_px;
  out.rms_px = last.rms_work_px / std::max(out.work_scale, 1e-9);
  out.trace += fmt::format(
      " silhouettes: {} pairs, RMS {:.2f} px, {:.0f} % of the model edges on a photo edge, "
      "MI {:.3f}",
      out.inliers, out.rms_px, 100 * out.edge_share, out.mutual_information);
  out.ok = out.edge_share >= options.min_edge_share && out.fine_edge_share >= options.min_fine_edge_share &&
           out.mutual_information >= options.min_mutual_information && out.inliers >= options.min_pairs;
  return out;
}

}  // namespace lidarshop
