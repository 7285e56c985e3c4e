// The hand-made scans of segment_test and segment_window_test, and the blocks of whole_object_test and
// strips_test (test helpers).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/random_scene.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment_eval.h"

namespace lidarshop::segment_test {

constexpr double kPi = 3.14159265358979323846;

// Random scene `seed` as `segment_eval --random-seeds` sees it: its scan, the target's cells and the two
// automatic strokes (upper part, background below; stroke seed 7919 · seed + 1).
struct RandomEvalCase {
  SceneDescription scene;
  Scan scan;
  cv::Mat truth, strokes;
};
inline RandomEvalCase MakeRandomEvalCase(uint64_t seed) {
  RandomEvalCase c;
  c.scene = RandomScene(seed);
  c.scan = SynthesizeScan(c.scene);
  c.truth = (c.scan.label == c.scene.target_label) & (c.scan.valid != 0);
  EvalStrokeOptions stroke_options;
  stroke_options.upper_and_below = true;
  c.strokes = MakeEvalStrokes(c.truth, c.scan.valid, seed * 7919 + 1, stroke_options);
  return c;
}

// An axis-aligned box for analytic scans (testing/analytic_scan.h).
struct Block {
  cv::Vec3d lo, hi;  // axis-aligned box corners, metres (scanner at the origin, z up)
  cv::Vec3b rgb;
  int label;
};

// Distance along `d` to the box (slab method), infinity when missed.
inline double HitBlock(const cv::Vec3f& d, const Block& block) {
  double t_near = 0, t_far = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (0 < block.lo[i] || 0 > block.hi[i]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = block.lo[i] / d[i], t1 = block.hi[i] / d[i];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  return t_near <= t_far ? t_near : std::numeric_limits<double>::infinity();
}

// A hand-made scan (analytic ray casting): a box face 1.2 m wide and 1.3 m tall at y = 8 m standing on a
// ground plane 1.5 m below the scanner, a wall at y = 20 m behind, sky (no return) above the wall. The box's
// colour is `box_rgb`; the ground is noisy green, the wall brick red. Label 1 = box, 0 = the rest.
inline Scan MakeBoxOnGround(int rows, int cols, cv::Vec3b box_rgb, uint64_t seed,
                            double range_noise_m = 0.005) {
  Scan scan = MakeScan(rows, cols, /*with_color=*/true);
  scan.grid = UniformGrid(rows, cols, -20 * kPi / 180, 20 * kPi / 180, -25 * kPi / 180, 10 * kPi / 180);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.label = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNoLabel));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(row, col);
      double t = std::numeric_limits<double>::infinity();
      int label = kNoLabel;
      cv::Vec3b rgb;
      const double g1 = noise(rng), g2 = noise(rng);
      if (d[2] < 0) {  // ground z = -1.5
        const double tg = -1.5 / d[2];
        if (tg < t && tg * d[1] < 30) {
          t = tg;
          label = 0;
          rgb = cv::Vec3b(cv::saturate_cast<uint8_t>(74 + 20 * g1), cv::saturate_cast<uint8_t>(112 + 25 * g2),
                          cv::saturate_cast<uint8_t>(42 + 10 * g1));
        }
      }
      {  // box face y = 8
        const double tb = 8.0 / d[1];
        const double x = tb * d[0], z = tb * d[2];
        if (std::abs(x) <= 0.6 && z >= -1.5 && z <= -0.2 && tb < t) {
          t = tb;
          label = 1;
          rgb = cv::Vec3b(cv::saturate_cast<uint8_t>(box_rgb[0] + 6 * g1),
                          cv::saturate_cast<uint8_t>(box_rgb[1] + 6 * g2),
                          cv::saturate_cast<uint8_t>(box_rgb[2] + 6 * g1));
        }
      }
      {  // wall y = 20
        const double tw = 20.0 / d[1];
        const double z = tw * d[2];
        if (z >= -1.5 && z <= 3.0 && tw < t) {
          t = tw;
          label = 0;
          rgb = cv::Vec3b(cv::saturate_cast<uint8_t>(170 + 15 * g1), 80, 60);
        }
      }
      if (label == kNoLabel) continue;
      const double range = t + range_noise_m * noise(rng);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.range.at<float>(row, col) = static_cast<float>(range);
      scan.point.at<cv::Vec3f>(row, col) = d * static_cast<float>(range);
      scan.color.at<cv::Vec3b>(row, col) = rgb;
      scan.label.at<int32_t>(row, col) = label;
    }
  }
  return scan;
}

inline cv::Mat TruthMask(const Scan& scan) { return scan.label == 1; }

}  // namespace lidarshop::segment_test
