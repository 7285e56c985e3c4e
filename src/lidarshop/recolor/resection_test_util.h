// Shared by the resection tests (resection_test.cc, recolor_warnings_test.cc): a camera beside a scanner and
// pixel-point pairs it sees, with noise and outliers drawn from a seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/recolor/resection.h"

namespace lidarshop::testing_resection {

inline PinholeCamera TrueCamera() {
  PinholeCamera camera;
  camera.width_px = 1024;
  camera.height_px = 768;
  camera.fx_px = camera.fy_px = 850;
  camera.cx_px = 515.3;
  camera.cy_px = 380.9;
  // Looking along +y (world) from beside a scanner: camera z = world y, camera x = world x, camera y = -z.
  camera.world_from_camera = ComposeTransform({1.5, 0.3, 1.4}, {-92, 3, 8});
  return camera;
}

// `count` points 3-9 m in front of the camera, seen inside the image; noise on the pixels and a fraction of
// outliers (pixels moved by 20-200 px). `noise_px` is the RMS length of the pixel error (σ = noise / √2 per
// axis). `truth` gets the noise-free pairs.
inline std::vector<PixelPointPair> MakePairs(const PinholeCamera& camera, int count, double noise_px,
                                             double outlier_fraction, uint64_t seed,
                                             std::vector<PixelPointPair>* truth = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> gauss(0, noise_px / std::sqrt(2.0));
  std::vector<PixelPointPair> pairs;
  const int outliers = static_cast<int>(std::round(outlier_fraction * count));
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d pixel(20 + unit(rng) * (camera.width_px - 40),
                                20 + unit(rng) * (camera.height_px - 40));
    const double depth = 3 + 6 * unit(rng);
    const Eigen::Vector3d in_camera = depth * UnprojectPixel(camera, pixel);
    PixelPointPair pair{
        pixel, camera.world_from_camera.topLeftCorner<3, 3>() * in_camera + camera.center_in_world()};
    if (truth) truth->push_back(pair);
    pair.pixel_px += Eigen::Vector2d(gauss(rng), gauss(rng));
    if (i < outliers) {
      const double angle = 2 * M_PI * unit(rng), length = 20 + 180 * unit(rng);
      pair.pixel_px += length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    pairs.push_back(pair);
  }
  return pairs;
}

}  // namespace lidarshop::testing_resection
