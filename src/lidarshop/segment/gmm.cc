#include "lidarshop/segment/gmm.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>

namespace lidarshop {

template <int D>
Gmm<D> FitGmm(const std::vector<Eigen::Matrix<double, D, 1>>& x, int components, int iterations,
              double var_floor, uint64_t seed) {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  const int n = static_cast<int>(x.size());
  const int k = std::max(1, std::min(components, n));
  std::mt19937_64 rng(seed);
  // k-means++ seeding.
  std::vector<Vec> centre;
  centre.push_back(x[std::uniform_int_distribution<int>(0, n - 1)(rng)]);
  std::vector<double> d2(n, std::numeric_limits<double>::max());
  while (static_cast<int>(centre.size()) < k) {
    double total = 0;
    for (int i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (x[i] - centre.back()).squaredNorm());
      total += d2[i];
    }
    if (total <= 0) break;
    double pick = std::uniform_real_distribution<double>(0, total)(rng);
    int chosen = n - 1;
    for (int i = 0; i < n; ++i) {
      pick -= d2[i];
      if (pick <= 0) {
        chosen = i;
        break;
      }
    }
    centre.push_back(x[chosen]);
  }
  const int kk = static_cast<int>(centre.size());
  // Responsibilities start hard (nearest centre), then EM.
  std::vector<double> resp(static_cast<size_t>(n) * kk, 0.0);
  for (int i = 0; i < n; ++i) {
    int best = 0;
    for (int j = 1; j < kk; ++j) {
      if ((x[i] - centre[j]).squaredNorm() < (x[i] - centre[best]).squaredNorm()) best = j;
    }
    resp[static_cast<size_t>(i) * kk + best] = 1.0;
  }
  Gmm<D> g;
  auto m_step = [&]() {
    g.log_weight.assign(kk, 0);
    g.mean.assign(kk, Vec::Zero());
    g.inv_cov.assign(kk, Mat::Identity());
    g.log_norm.assign(kk, 0);
    for (int j = 0; j < kk; ++j) {
      double wsum = 0;
      Vec m = Vec::Zero();
      for (int i = 0; i < n; ++i) {
        const double r = resp[static_cast<size_t>(i) * kk + j];
        wsum += r;
        m += r * x[i];
      }
      if (wsum < 1e-9) {
        g.log_weight[j] = -1e30;
        g.log_norm[j] = -1e30;
        continue;
      }
      m /= wsum;
      Mat c = Mat::Zero();
      for (int i = 0; i < n; ++i) {
        const double r = resp[static_cast<size_t>(i) * kk + j];
        const Vec diff = x[i] - m;
        c += r * diff * diff.transpose();
      }
      c /= wsum;
      c.diagonal().array() += var_floor;
      g.mean[j] = m;
      g.inv_cov[j] = c.inverse();
      g.log_weight[j] = std::log(wsum / n);
      g.log_norm[j] = g.log_weight[j] - 0.5 * (D * std::log(2 * M_PI) + std::log(c.determinant()));
    }
  };
  m_step();
  for (int it = 0; it < iterations; ++it) {
    for (int i = 0; i < n; ++i) {
      double t[32], best = -std::numeric_limits<double>::infinity();
      for (int j = 0; j < kk; ++j) {
        const Vec diff = x[i] - g.mean[j];
        t[j] = g.log_norm[j] - 0.5 * diff.dot(g.inv_cov[j] * diff);
        best = std::max(best, t[j]);
      }
      double s = 0;
      for (int j = 0; j < kk; ++j) s += (t[j] = std::exp(t[j] - best));
      for (int j = 0; j < kk; ++j) resp[static_cast<size_t>(i) * kk + j] = t[j] / s;
    }
    m_step();
  }
  return g;
}

template Gmm<1> FitGmm<1>(const std::vector<Eigen::Matrix<double, 1, 1>>&, int, int, double, uint64_t);
template Gmm<3> FitGmm<3>(const std::vector<Eigen::Matrix<double, 3, 1>>&, int, int, double, uint64_t);

}  // namespace lidarshop
