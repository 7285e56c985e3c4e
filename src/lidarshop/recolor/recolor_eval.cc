#include "lidarshop/recolor/recolor_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/recolor/station_recolor.h"

namespace lidarshop {

std::string RecolorScore::Summary() const {
  return fmt::format(
      "visible {} ({} recoloured, {:.2f} % correct, {:.2f} % a wrong colour), hidden {} ({:.2f} % changed; "
      "{} behind another object, {} of them changed), outside {}",
      visible, visible_recolored, visible_correct_percent(), visible_wrong_percent(), hidden,
      hidden_changed_percent(), hidden_behind, hidden_behind_changed, outside);
}

RecolorScore ScoreRecolor(const SceneDescription& scene, const Scan& truth, const Scan& input,
                          const Scan& output, const PinholeCamera& camera, int max_level_difference,
                          double visibility_tolerance_m, double behind_object_m) {
  RaycastScene raycast;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    raycast.AddMesh(MeshInWorld(scene.objects[i]), static_cast<int32_t>(i));
  raycast.Commit();
  const Eigen::Vector3d center = camera.center_in_world();
  std::vector<Ray> rays;
  std::vector<int64_t> cells;
  RecolorScore score;
  for (int r = 0; r < truth.rows; ++r) {
    for (int c = 0; c < truth.cols; ++c) {
      if (!truth.valid.at<uint8_t>(r, c)) continue;
      const cv::Vec3f p = truth.point.at<cv::Vec3f>(r, c);
      const Eigen::Vector3d point_in_world =
          (truth.world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1)).head<3>();
      Eigen::Vector2d pixel;
      if (!ProjectWorldPoint(camera, point_in_world, &pixel) || !InsideImage(camera, pixel)) {
        ++score.outside;
        continue;
      }
      Ray ray;
      const Eigen::Vector3d segment = point_in_world - center;
      ray.origin = center.cast<float>();
      ray.direction = segment.cast<float>();
      rays.push_back(ray);
      cells.push_back(static_cast<int64_t>(r) * truth.cols + c);
    }
  }
  // The first hit along each ray (t in units of the segment to the point): hidden when it lies more than the
  // tolerance before the point.
  std::vector<RayHit> hits(rays.size());
  raycast.Cast(rays, hits);
  for (size_t i = 0; i < cells.size(); ++i) {
    const int r = static_cast<int>(cells[i] / truth.cols), c = static_cast<int>(cells[i] % truth.cols);
    const cv::Vec3b before = input.color.at<cv::Vec3b>(r, c), after = output.color.at<cv::Vec3b>(r, c);
    const double length = rays[i].direction.cast<double>().norm();
    const double gap_m = (1.0 - hits[i].t_hit) * length;  // how far before the point the first hit lies
    if (std::isfinite(hits[i].t_hit) && gap_m > visibility_tolerance_m) {
      ++score.hidden;
      score.hidden_changed += before != after;
      if (gap_m > behind_object_m) {
        ++score.hidden_behind;
        score.hidden_behind_changed += before != after;
      }
      continue;
    }
    ++score.visible;
    score.visible_recolored += before != after;
    const cv::Vec3b true_color = truth.color.at<cv::Vec3b>(r, c);
    bool close = true;
    for (int k = 0; k < 3; ++k) close = close && std::abs(after[k] - true_color[k]) <= max_level_difference;
    score.visible_correct += close;
    score.visible_wrong += before != after && !close;
  }
  return score;
}

std::vector<PixelPointPair> DrawCorrespondences(const Scan& scan, const PinholeCamera& camera,
                                                const cv::Mat& photo_depth_m, int count, double noise_px,
                                                double outlier_fraction, uint64_t seed,
                                                std::vector<PixelPointPair>* exact) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0, noise_px / std::sqrt(2.0));
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<PixelPointPair> pairs;
  const int outlier_count = static_cast<int>(std::round(outlier_fraction * count));
  while (static_cast<int>(pairs.size()) < count) {
    const int r = static_cast<int>(unit(rng) * scan.rows), c = static_cast<int>(unit(rng) * scan.cols);
    if (!scan.valid.at<uint8_t>(r, c)) continue;
    const Eigen::Vector3d world = WorldPointOfCell(scan, r, c);
    Eigen::Vector2d pixel;
    if (!ProjectWorldPoint(camera, world, &pixel) || !InsideImage(camera, pixel)) continue;
    const int pr = static_cast<int>(pixel.y()), pc = static_cast<int>(pixel.x());
    if (std::abs(photo_depth_m.at<float>(pr, pc) - (world - camera.center_in_world()).norm()) > 0.02)
      continue;  // hidden
    if (exact) exact->push_back({pixel, world});
    PixelPointPair noisy{pixel + Eigen::Vector2d(gauss(rng), gauss(rng)), world};
    if (static_cast<int>(pairs.size()) < outlier_count) {
      const double angle = 2 * M_PI * unit(rng), length = 20 + 180 * unit(rng);
      noisy.pixel_px += length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    pairs.push_back(noisy);
  }
  return pairs;
}

PinholeCamera EvaluationCamera(double offset_m) {
  const Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 1.5) + offset_m * Eigen::Vector3d(0.8, -0.6, 0.05);
  return CameraLookingAt(eye, {0, 10, 1.0}, 800, 600, 70);
}

double RmsReprojectionError(const PinholeCamera& camera, const std::vector<PixelPointPair>& pairs) {
  double sum = 0;
  for (const PixelPointPair& pair : pairs) {
    const double e = ReprojectionError(camera, pair);
    sum += std::isfinite(e) ? e * e : 1e12;
  }
  return pairs.empty() ? 0.0 : std::sqrt(sum / pairs.size());
}

StationColourScore ScoreStationColours(const Scan& truth, const PhotosRecolorResult& result) {
  StationColourScore score;
  const cv::Mat& photo = result.photo_index;
  const cv::Mat& colour = result.scan.color;
  std::vector<double> errors;
  double seam_sum = 0, ordinary_sum = 0;
  int64_t ordinary_edges = 0;
  const auto step = [&](int r0, int c0, int r1, int c1) {
    const cv::Vec3i a = colour.at<cv::Vec3b>(r0, c0), b = colour.at<cv::Vec3b>(r1, c1);
    return (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3.0;
  };
  for (int r = 0; r < truth.rows; ++r) {
    for (int c = 0; c < truth.cols; ++c) {
      if (!truth.valid.at<uint8_t>(r, c)) continue;
      ++score.returns;
      const uint16_t here = photo.at<uint16_t>(r, c);
      if (here == 0) continue;
      ++score.coloured;
      const cv::Vec3i a = truth.color.at<cv::Vec3b>(r, c), b = colour.at<cv::Vec3b>(r, c);
      errors.push_back((std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3.0);
      for (const auto& [rn, cn] : {std::pair{r, c + 1}, std::pair{r + 1, c}}) {
        if (rn >= truth.rows || cn >= truth.cols) continue;
        const uint16_t there = photo.at<uint16_t>(rn, cn);
        if (there == 0) continue;
        if (there != here) {
          seam_sum += step(r, c, rn, cn);
          ++score.seam_edges;
        } else {
          ordinary_sum += step(r, c, rn, cn);
          ++ordinary_edges;
        }
      }
    }
  }
  if (!errors.empty()) {
    double sum = 0;
    for (const double e : errors) sum += e;
    score.mean_error = sum / static_cast<double>(errors.size());
    const size_t k =
        std::min(errors.size() - 1, static_cast<size_t>(0.95 * static_cast<double>(errors.size())));
    std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(k), errors.end());
    score.p95_error = errors[k];
  }
  score.seam_step = score.seam_edges ? seam_sum / static_cast<double>(score.seam_edges) : 0;
  score.ordinary_step = ordinary_edges ? ordinary_sum / static_cast<double>(ordinary_edges) : 0;
  return score;
}

}  // namespace lidarshop
