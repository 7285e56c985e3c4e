#include "lidarshop/testing/analytic_scan.h"

#include <random>

namespace lidarshop::test_scenes {

RayHit WallAndGround(const cv::Vec3f& d, double wall_y_m, const cv::Vec3b& ground_rgb) {
  RayHit hit{wall_y_m / d[1], cv::Vec3b(210, 198, 176), 0};
  if (d[2] < 0 && -1.5 / d[2] < hit.range_m) hit = {-1.5 / d[2], ground_rgb, 0};
  return hit;
}

Scan MakeAnalyticScan(const AnalyticGrid& grid, const std::function<RayHit(const cv::Vec3f&)>& hit,
                      double range_noise_m, uint64_t seed) {
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  Scan scan = MakeScan(grid.rows, grid.cols, /*with_color=*/true);
  scan.grid =
      UniformGrid(grid.rows, grid.cols, grid.azimuth_min_deg * kDegree, grid.azimuth_max_deg * kDegree,
                  grid.elevation_min_deg * kDegree, grid.elevation_max_deg * kDegree);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.label = cv::Mat(grid.rows, grid.cols, CV_32S, cv::Scalar(kNoLabel));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(row, col);
      const RayHit h = hit(d);
      const double g = noise(rng);
      const double range = h.range_m + range_noise_m * noise(rng);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.range.at<float>(row, col) = static_cast<float>(range);
      scan.point.at<cv::Vec3f>(row, col) = d * static_cast<float>(range);
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(cv::saturate_cast<uint8_t>(h.rgb[0] + 5 * g),
                                                     cv::saturate_cast<uint8_t>(h.rgb[1] + 5 * g),
                                                     cv::saturate_cast<uint8_t>(h.rgb[2] + 5 * g));
      scan.label.at<int32_t>(row, col) = h.label;
    }
  }
  return scan;
}

}  // namespace lidarshop::test_scenes
