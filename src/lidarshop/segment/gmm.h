// A Gaussian mixture in D dimensions with full covariances, fitted with k-means++ seeding and EM. Generic (it
// knows nothing of scans); the segmentation's appearance models use D = 3 (colour) and D = 1 (range).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace lidarshop {

template <int D>
struct Gmm {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  std::vector<double> log_weight;
  std::vector<Vec> mean;
  std::vector<Mat> inv_cov;
  std::vector<double> log_norm;  // log of the normalisation constant incl. the weight

  // log p(x), by log-sum-exp over the components (at most 32).
  double LogDensity(const Vec& x) const {
    double best = -std::numeric_limits<double>::infinity();
    double terms[32];
    const int k = static_cast<int>(mean.size());
    for (int j = 0; j < k; ++j) {
      const Vec diff = x - mean[j];
      terms[j] = log_norm[j] - 0.5 * diff.dot(inv_cov[j] * diff);
      best = std::max(best, terms[j]);
    }
    double s = 0;
    for (int j = 0; j < k; ++j) s += std::exp(terms[j] - best);
    return best + std::log(s);
  }
};

// Fits `components` Gaussians (fewer when there are fewer samples; at most 32) to the samples `x` (at least
// one): k-means++ seeding with `seed`, hard nearest-centre responsibilities, then `iterations` EM steps.
// `var_floor` is added to every covariance's diagonal (units of x squared). Deterministic for a seed.
// Instantiated for D = 1 and D = 3 (gmm.cc).
template <int D>
Gmm<D> FitGmm(const std::vector<Eigen::Matrix<double, D, 1>>& x, int components, int iterations,
              double var_floor, uint64_t seed);

}  // namespace lidarshop
