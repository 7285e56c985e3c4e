#include "lidarshop/segment/segment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <fmt/format.h>
#include <maxflow/graph.h>
#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

void CutWeights::Check() const { Validate(*this); }

void SegmentOptions::Check() const { Validate(*this); }

std::string SegmentResult::Summary() const {
  return fmt::format(
      "{} object cells, flow {:.1f}, {:.3f} s (features {:.3f}, models {:.3f}, graph {:.3f}, "
      "max-flow {:.3f})",
      object_cells, flow, timings.total_s, timings.features_s, timings.models_s, timings.graph_s,
      timings.maxflow_s);
}

namespace {

using Graph = maxflow::Graph<float, float, float>;

void ThrowGraphError(const char* message) { throw std::runtime_error(fmt::format("maxflow: {}", message)); }

// The valid cells as graph nodes, with their standardized channels.
struct Nodes {
  int rows = 0, cols = 0;
  std::vector<int32_t> node_of_cell;  // rows*cols, -1 = no return
  std::vector<int32_t> cell_of_node;  // #nodes
  std::vector<cv::Vec4f> raw;         // #nodes: R, G, B in [0, 1], range in metres
  std::vector<cv::Vec4f> standard;    // #nodes: the same, standardized over the valid cells
  float range_min = 0, range_max = 0;
  int num() const { return static_cast<int>(cell_of_node.size()); }
};

Nodes MakeNodes(const Scan& scan) {
  Nodes nodes;
  nodes.rows = scan.rows;
  nodes.cols = scan.cols;
  const cv::Mat rgbd = RgbdImage(scan);
  nodes.node_of_cell.assign(scan.num_cells(), -1);
  for (int row = 0; row < scan.rows; ++row) {
    const uint8_t* valid = scan.valid.ptr<uint8_t>(row);
    const float* range = scan.range.ptr<float>(row);
    for (int col = 0; col < scan.cols; ++col) {
      if (valid[col] == 0 || !std::isfinite(range[col]) || range[col] <= 0) continue;
      const int64_t cell = static_cast<int64_t>(row) * scan.cols + col;
      nodes.node_of_cell[cell] = static_cast<int32_t>(nodes.cell_of_node.size());
      nodes.cell_of_node.push_back(static_cast<int32_t>(cell));
      nodes.raw.push_back(rgbd.at<cv::Vec4f>(row, col));
    }
  }
  const int n = nodes.num();
  if (n == 0) return nodes;
  double sum[4] = {0, 0, 0, 0}, sum2[4] = {0, 0, 0, 0};
  nodes.range_min = std::numeric_limits<float>::max();
  nodes.range_max = 0;
  for (const cv::Vec4f& v : nodes.raw) {
    for (int c = 0; c < 4; ++c) {
      sum[c] += v[c];
      sum2[c] += double(v[c]) * v[c];
    }
    nodes.range_min = std::min(nodes.range_min, v[3]);
    nodes.range_max = std::max(nodes.range_max, v[3]);
  }
  cv::Vec4f mean, inv_std;
  for (int c = 0; c < 4; ++c) {
    mean[c] = static_cast<float>(sum[c] / n);
    const double var = std::max(0.0, sum2[c] / n - (sum[c] / n) * (sum[c] / n));
    inv_std[c] = var > 1e-12 ? static_cast<float>(1.0 / std::sqrt(var)) : 1.0f;
  }
  nodes.standard.resize(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          for (int c = 0; c < 4; ++c) nodes.standard[i][c] = (nodes.raw[i][c] - mean[c]) * inv_std[c];
        }
      },
      4096);
  return nodes;
}

// Neighbour offsets in the order right, down, down-right, down-left (each edge is
// stored once, at its upper/left end).
constexpr int kDirRow[4] = {0, 1, 1, 1};
constexpr int kDirCol[4] = {1, 0, 1, -1};

// n-link weights of one cut: weight[d][node] for direction d (0 when there is no neighbour), already times γ.
struct NLinks {
  int directions = 2;
  std::vector<float> weight[4];
  double sigma2 = 0;  // the estimated σ² (standardized units)
};

NLinks ComputeNLinks(const Nodes& nodes, const CutWeights& w, bool eight_connected, double sigma_scale) {
  NLinks links;
  links.directions = eight_connected ? 4 : 2;
  const int n = nodes.num();
  const float lambda[4] = {float(w.lambda_r), float(w.lambda_g), float(w.lambda_b), float(w.lambda_d)};
  for (int d = 0; d < links.directions; ++d) links.weight[d].assign(n, -1.0f);
  // Pass 1: weighted squared differences, with per-row partial sums so the σ
  // estimate does not depend on threads.
  std::vector<double> row_sum(nodes.rows, 0.0);
  std::vector<int64_t> row_count(nodes.rows, 0);
  ParallelFor(nodes.rows, [&](int64_t row) {
    double s = 0;
    int64_t count = 0;
    for (int col = 0; col < nodes.cols; ++col) {
      const int32_t p = nodes.node_of_cell[row * nodes.cols + col];
      if (p < 0) continue;
      for (int d = 0; d < links.directions; ++d) {
        const int r2 = static_cast<int>(row) + kDirRow[d], c2 = col + kDirCol[d];
        if (r2 >= nodes.rows || c2 < 0 || c2 >= nodes.cols) continue;
        const int32_t q = nodes.node_of_cell[static_cast<int64_t>(r2) * nodes.cols + c2];
        if (q < 0) continue;
        float d2 = 0;
        for (int c = 0; c < 4; ++c) {
          const float diff = nodes.standard[p][c] - nodes.standard[q][c];
          d2 += lambda[c] * diff * diff;
        }
        links.weight[d][p] = d2;
        s += d2;
        ++count;
      }
    }
    row_sum[row] = s;
    row_count[row] = count;
  });
  const double total = std::accumulate(row_sum.begin(), row_sum.end(), 0.0);
  const int64_t count = std::accumulate(row_count.begin(), row_count.end(), int64_t{0});
  const double mean = count > 0 ? total / count : 0.0;
  double typical = mean;
  if (w.median_sigma && count > 0) {
    // Median over a deterministic stride sample of at most ~200k n-links.
    const int64_t stride = std::max<int64_t>(1, n / 100000);
    std::vector<float> sample;
    for (int64_t i = 0; i < n; i += stride) {
      for (int d = 0; d < links.directions; ++d) {
        if (links.weight[d][i] >= 0) sample.push_back(links.weight[d][i]);
      }
    }
    if (!sample.empty()) {
      std::nth_element(sample.begin(), sample.begin() + sample.size() / 2, sample.end());
      typical = std::max(0.01 * mean, double(sample[sample.size() / 2]));
    }
  }
  links.sigma2 = std::max(1e-12, sigma_scale * sigma_scale * typical);
  const float inv_two_sigma2 = static_cast<float>(1.0 / (2.0 * links.sigma2));
  // Pass 2: weights.
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int d = 0; d < links.directions; ++d) {
          const float scale = static_cast<float>(w.smoothness / (d < 2 ? 1.0 : std::sqrt(2.0)));
          float* weight = links.weight[d].data();
          for (int64_t i = begin; i < end; ++i) {
            weight[i] = weight[i] < 0 ? 0.0f : scale * std::exp(-weight[i] * inv_two_sigma2);
          }
        }
      },
      4096);
  return links;
}

// ---- appearance models: log densities of colour (per unit volume of [0,1]^3) and range (per metre) ----

struct LogDensities {
  std::vector<float> color_object, color_background, depth_object, depth_background;  // #nodes
};

// Histogram density (per unit volume) with a [1 2 1] smoothing along each axis.
std::vector<float> ColorHistogram(const Nodes& nodes, const std::vector<int32_t>& members, int bins) {
  const int b3 = bins * bins * bins;
  std::vector<double> h(b3, 0.0), tmp(b3, 0.0);
  auto bin_of = [bins](float v) { return std::clamp(static_cast<int>(v * bins), 0, bins - 1); };
  for (int32_t i : members) {
    const cv::Vec4f& v = nodes.raw[i];
    h[(bin_of(v[0]) * bins + bin_of(v[1])) * bins + bin_of(v[2])] += 1.0;
  }
  const int stride[3] = {bins * bins, bins, 1};
  for (int axis = 0; axis < 3; ++axis) {
    for (int idx = 0; idx < b3; ++idx) {
      const int coord = (idx / stride[axis]) % bins;
      double s = 2 * h[idx], wsum = 2;
      if (coord > 0) s += h[idx - stride[axis]], wsum += 1;
      if (coord < bins - 1) s += h[idx + stride[axis]], wsum += 1;
      tmp[idx] = s / wsum;
    }
    h.swap(tmp);
  }
  const double total = std::accumulate(h.begin(), h.end(), 0.0);
  std::vector<float> density(b3);
  for (int idx = 0; idx < b3; ++idx) density[idx] = static_cast<float>(total > 0 ? h[idx] / total * b3 : 1.0);
  return density;
}

std::vector<float> DepthHistogram(const Nodes& nodes, const std::vector<int32_t>& members, double bin_m,
                                  double smoothing_m, int num_bins) {
  std::vector<double> h(num_bins, 0.0);
  for (int32_t i : members) {
    const int b = std::clamp(static_cast<int>((nodes.raw[i][3] - nodes.range_min) / bin_m), 0, num_bins - 1);
    h[b] += 1.0;
  }
  const double sigma_bins = smoothing_m / bin_m;
  if (sigma_bins > 0.1) {
    const int radius = static_cast<int>(std::ceil(3 * sigma_bins));
    std::vector<double> kernel(2 * radius + 1);
    for (int k = -radius; k <= radius; ++k)
      kernel[k + radius] = std::exp(-0.5 * k * k / (sigma_bins * sigma_bins));
    std::vector<double> out(num_bins, 0.0);
    for (int b = 0; b < num_bins; ++b) {
      if (h[b] == 0) continue;
      for (int k = -radius; k <= radius; ++k) {
        if (b + k >= 0 && b + k < num_bins) out[b + k] += h[b] * kernel[k + radius];
      }
    }
    h.swap(out);
  }
  const double total = std::accumulate(h.begin(), h.end(), 0.0);
  std::vector<float> density(num_bins);
  for (int b = 0; b < num_bins; ++b) density[b] = static_cast<float>(total > 0 ? h[b] / total / bin_m : 0.0);
  return density;
}

// A Gaussian mixture in D dimensions (full covariance), fitted with k-means++ seeding and EM.
template <int D>
struct Gmm {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  std::vector<double> log_weight;
  std::vector<Vec> mean;
  std::vector<Mat> inv_cov;
  std::vector<double> log_norm;  // log of the normalisation constant incl. the weight

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

// log((1 − u) p + u · uniform) for every node, given the model density p computed by `density(node)`.
template <typename F>
std::vector<float> MixWithUniform(int n, double uniform_weight, double uniform_density, F density) {
  std::vector<float> out(n);
  const float u = static_cast<float>(uniform_weight * uniform_density),
              keep = static_cast<float>(1 - uniform_weight);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) out[i] = std::log(keep * density(static_cast<int32_t>(i)) + u);
      },
      4096);
  return out;
}

// The table log((1 − u) p + u · uniform) of a table of densities p: the same float expression as
// MixWithUniform, evaluated once per entry instead of once per node.
std::vector<float> LogMixTable(const std::vector<float>& density, double uniform_weight,
                               double uniform_density) {
  std::vector<float> out(density.size());
  const float u = static_cast<float>(uniform_weight * uniform_density),
              keep = static_cast<float>(1 - uniform_weight);
  ParallelForRange(
      static_cast<int64_t>(density.size()),
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) out[i] = std::log(keep * density[i] + u);
      },
      4096);
  return out;
}

// out[k] = table[index(k)] for k < n.
template <typename F>
std::vector<float> LookUp(int n, const std::vector<float>& table, F index) {
  std::vector<float> out(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k) out[k] = table[index(static_cast<int32_t>(k))];
      },
      4096);
  return out;
}

// Log densities of the nodes `subset` (nullptr = every node; the outputs are indexed like `subset`) under the
// models learnt from the nodes `object` and `background`.
LogDensities ComputeLogDensities(const Nodes& nodes, const std::vector<int32_t>& object,
                                 const std::vector<int32_t>& background, const SegmentOptions& options,
                                 const std::vector<int32_t>* subset = nullptr) {
  LogDensities out;
  const int n = subset != nullptr ? static_cast<int>(subset->size()) : nodes.num();
  auto node = [subset](int32_t k) { return subset != nullptr ? (*subset)[k] : k; };
  const double span_m = std::max(double(nodes.range_max - nodes.range_min), options.depth_bin_m);
  const double depth_uniform = 1.0 / span_m;
  if (options.model == AppearanceModel::kHistogram) {
    const int bins = options.color_bins;
    auto color_index = [&](int32_t i) {
      const cv::Vec4f& v = nodes.raw[node(i)];
      auto b = [bins](float x) { return std::clamp(static_cast<int>(x * bins), 0, bins - 1); };
      return (b(v[0]) * bins + b(v[1])) * bins + b(v[2]);
    };
    const int depth_bins = std::min(1 << 20, static_cast<int>(span_m / options.depth_bin_m) + 1);
    auto depth_index = [&](int32_t i) {
      return std::clamp(static_cast<int>((nodes.raw[node(i)][3] - nodes.range_min) / options.depth_bin_m), 0,
                        depth_bins - 1);
    };
    const std::vector<float> co = ColorHistogram(nodes, object, bins);
    const std::vector<float> cb = ColorHistogram(nodes, background, bins);
    const std::vector<float> dob =
        DepthHistogram(nodes, object, options.depth_bin_m, options.depth_smoothing_m, depth_bins);
    const std::vector<float> dbg =
        DepthHistogram(nodes, background, options.depth_bin_m, options.depth_smoothing_m, depth_bins);
    out.color_object =
        MixWithUniform(n, options.object_uniform, 1.0, [&](int32_t i) { return co[color_index(i)]; });
    out.color_background =
        MixWithUniform(n, options.background_uniform, 1.0, [&](int32_t i) { return cb[color_index(i)]; });
    out.depth_object = MixWithUniform(n, options.object_uniform, depth_uniform,
                                      [&](int32_t i) { return dob[depth_index(i)]; });
    out.depth_background = MixWithUniform(n, options.background_uniform, depth_uniform,
                                          [&](int32_t i) { return dbg[depth_index(i)]; });
    return out;
  }
  // Gaussian mixtures: colour (3-D, full covariance) and range (1-D), fitted on at most 8000 members (a
  // fixed stride, deterministic).
  auto fit = [&](const std::vector<int32_t>& members, uint64_t seed, Gmm<3>* color, Gmm<1>* depth) {
    const size_t stride = std::max<size_t>(1, members.size() / 8000);
    std::vector<Eigen::Vector3d> xc;
    std::vector<Eigen::Matrix<double, 1, 1>> xd;
    for (size_t k = 0; k < members.size(); k += stride) {
      const cv::Vec4f& v = nodes.raw[members[k]];
      xc.emplace_back(v[0], v[1], v[2]);
      xd.push_back(Eigen::Matrix<double, 1, 1>(v[3]));
    }
    const double depth_floor = std::max(options.depth_smoothing_m, options.depth_bin_m);
    *color = FitGmm<3>(xc, options.gmm_components, options.gmm_iterations, 1e-4, seed);
    *depth =
        FitGmm<1>(xd, options.gmm_components, options.gmm_iterations, depth_floor * depth_floor, seed + 1);
  };
  Gmm<3> co, cb;
  Gmm<1> dob, dbg;
  fit(object, options.seed, &co, &dob);
  fit(background, options.seed + 2, &cb, &dbg);
  // The colour mixtures are tabulated on a 64^3 grid of cell centres (build once, look up per node): 262,144
  // evaluations instead of one per node, at most half a 64th of the range off in each channel.
  constexpr int kLut = 64;
  auto tabulate = [&](const Gmm<3>& g) {
    std::vector<float> lut(kLut * kLut * kLut);
    ParallelFor(kLut, [&](int64_t r) {
      for (int gg = 0; gg < kLut; ++gg) {
        for (int b = 0; b < kLut; ++b) {
          const Eigen::Vector3d x((r + 0.5) / kLut, (gg + 0.5) / kLut, (b + 0.5) / kLut);
          lut[(r * kLut + gg) * kLut + b] = static_cast<float>(std::exp(g.LogDensity(x)));
        }
      }
    });
    return lut;
  };
  const std::vector<float> lut_object = tabulate(co), lut_background = tabulate(cb);
  auto lut_index = [&](int32_t i) {
    const cv::Vec4f& v = nodes.raw[node(i)];
    auto q = [](float x) { return std::clamp(static_cast<int>(x * kLut), 0, kLut - 1); };
    return (q(v[0]) * kLut + q(v[1])) * kLut + q(v[2]);
  };
  // The range mixtures likewise, on a grid of an eighth of the variance floor (at most 2^20 entries).
  const double depth_step_m =
      std::max(std::max(options.depth_smoothing_m, options.depth_bin_m) / 8.0, span_m / double(1 << 20));
  const int depth_entries = static_cast<int>(span_m / depth_step_m) + 2;
  auto tabulate_depth = [&](const Gmm<1>& g) {
    std::vector<float> lut(depth_entries);
    ParallelForRange(
        depth_entries,
        [&](int64_t begin, int64_t end) {
          for (int64_t k = begin; k < end; ++k) {
            const double range = nodes.range_min + (k + 0.5) * depth_step_m;
            lut[k] = static_cast<float>(std::exp(g.LogDensity(Eigen::Matrix<double, 1, 1>(range))));
          }
        },
        1024);
    return lut;
  };
  const std::vector<float> depth_lut_object = tabulate_depth(dob), depth_lut_background = tabulate_depth(dbg);
  auto depth_index = [&](int32_t i) {
    return std::clamp(static_cast<int>((nodes.raw[node(i)][3] - nodes.range_min) / depth_step_m), 0,
                      depth_entries - 1);
  };
  // The logarithm and the uniform mixture are tabulated too, so a node costs two table look-ups per model.
  out.color_object = LookUp(n, LogMixTable(lut_object, options.object_uniform, 1.0), lut_index);
  out.color_background = LookUp(n, LogMixTable(lut_background, options.background_uniform, 1.0), lut_index);
  out.depth_object =
      LookUp(n, LogMixTable(depth_lut_object, options.object_uniform, depth_uniform), depth_index);
  out.depth_background =
      LookUp(n, LogMixTable(depth_lut_background, options.background_uniform, depth_uniform), depth_index);
  return out;
}

// Hard labels per node.
constexpr uint8_t kFree = 0, kHardObject = 1, kHardBackground = 2;

struct Cut {
  std::unique_ptr<Graph> graph;
  float hard_cap = 0;                       // capacity of a hard t-link
  std::vector<float> source_cap, sink_cap;  // #nodes: the t-link capacities given to the graph so far
  const CutWeights* weights = nullptr;      // the weights the graph was built with
  // The graph's nodes when it covers a region of interest only: graph node k is node node_of_local[k], and
  // local_of_node[i] is node i's graph node or -1. Both empty = the graph covers every node (k = i).
  std::vector<int32_t> node_of_local, local_of_node;
  std::vector<uint8_t> on_roi_edge;  // per graph node: on the ROI's edge inside the image
  const NLinks* links = nullptr;     // the n-links the graph was built with
  int num_local(int num_nodes) const {
    return node_of_local.empty() ? num_nodes : static_cast<int>(node_of_local.size());
  }
  int32_t Node(int32_t k) const { return node_of_local.empty() ? k : node_of_local[k]; }
};

// t-link capacities (source = object side, i.e. the cost of labelling the node background; sink = the cost of
// labelling it object) for every node from the models, or the hard capacity for hard nodes. `hard_cap` <= 0
// means "compute it" (1 + 8γ + the largest data cost) and returns it there.
void TLinkCapacities(const LogDensities& logp, const CutWeights& w, const std::vector<uint8_t>& hard,
                     float* hard_cap, std::vector<float>* source_cap, std::vector<float>* sink_cap) {
  const int n = static_cast<int>(hard.size());
  const float ac = static_cast<float>(w.color_data_weight), ad = static_cast<float>(w.depth_data_weight);
  const float bias = static_cast<float>(w.foreground_bias);
  source_cap->resize(n);
  sink_cap->resize(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          float cost_object = -(ac * logp.color_object[i] + ad * logp.depth_object[i]) + bias;
          float cost_background = -(ac * logp.color_background[i] + ad * logp.depth_background[i]);
          // Only the difference matters; keep both non-negative.
          const float m = std::min(cost_object, cost_background);
          (*source_cap)[i] = cost_background - m;
          (*sink_cap)[i] = cost_object - m;
        }
      },
      4096);
  if (*hard_cap <= 0) {
    float max_cost = 0;
    for (int i = 0; i < n; ++i) max_cost = std::max({max_cost, (*source_cap)[i], (*sink_cap)[i]});
    *hard_cap = static_cast<float>(1.0 + 8.0 * w.smoothness + max_cost);
  }
  for (int i = 0; i < n; ++i) {
    if (hard[i] == kHardObject) {
      (*source_cap)[i] = *hard_cap;
      (*sink_cap)[i] = 0;
    } else if (hard[i] == kHardBackground) {
      (*source_cap)[i] = 0;
      (*sink_cap)[i] = *hard_cap;
    }
  }
}

// Builds the graph of one cut and runs the max-flow. `hard` holds kFree / kHardObject / kHardBackground per
// graph node; `cut` comes with node_of_local / local_of_node set (or empty for the whole image), and `logp`
// and `hard` are indexed by graph node. n-links to nodes outside the graph are dropped.
void BuildAndCut(const Nodes& nodes, const NLinks& links, const LogDensities& logp, const CutWeights& w,
                 const std::vector<uint8_t>& hard, SegmentTimings* timings, double* flow, Cut* cut_out) {
  Timer timer;
  Cut& cut = *cut_out;
  const int n = cut.num_local(nodes.num());
  const bool subset = !cut.node_of_local.empty();
  int64_t num_edges = 0;
  for (int d = 0; d < links.directions; ++d) num_edges += n;
  cut.graph =
      std::make_unique<Graph>(n, static_cast<int>(std::min<int64_t>(num_edges, INT32_MAX)), ThrowGraphError);
  Graph& g = *cut.graph;
  g.add_node(n);
  // A hard t-link outweighs every n-link of its node and every data cost.
  TLinkCapacities(logp, w, hard, &cut.hard_cap, &cut.source_cap, &cut.sink_cap);
  cut.weights = &w;
  for (int k = 0; k < n; ++k) g.add_tweights(k, cut.source_cap[k], cut.sink_cap[k]);
  for (int k = 0; k < n; ++k) {
    const int32_t i = cut.Node(k);
    const int32_t cell = nodes.cell_of_node[i];
    const int row = cell / nodes.cols, col = cell % nodes.cols;
    for (int d = 0; d < links.directions; ++d) {
      const float weight = links.weight[d][i];
      if (weight <= 0) continue;
      int32_t q = nodes.node_of_cell[static_cast<int64_t>(row + kDirRow[d]) * nodes.cols + col + kDirCol[d]];
      if (subset) {
        q = cut.local_of_node[q];
        if (q < 0) continue;
      }
      g.add_edge(k, q, weight, weight);
    }
  }
  timings->graph_s += timer.Seconds();
  timer.Restart();
  *flow = g.maxflow();
  timings->maxflow_s += timer.Seconds();
}

// Object cells (255) from a cut, keeping only the 4-connected components that contain a cell of `keep` (node
// flags); cells of other components are dropped.
cv::Mat MaskFromCut(const Nodes& nodes, const Cut& cut, const std::vector<uint8_t>& hard) {
  cv::Mat mask(nodes.rows, nodes.cols, CV_8U, cv::Scalar(0));
  uint8_t* data = mask.ptr<uint8_t>();
  const int n = cut.num_local(nodes.num());
  for (int k = 0; k < n; ++k) {
    if (cut.graph->what_segment(k, Graph::SINK) == Graph::SOURCE) data[nodes.cell_of_node[cut.Node(k)]] = 255;
  }
  // Keep the components that hold a hard object cell.
  cv::Mat labels;
  const int count = cv::connectedComponents(mask, labels, 4, CV_32S);
  std::vector<uint8_t> keep(count, 0);
  const int32_t* label = labels.ptr<int32_t>();
  for (int i = 0; i < nodes.num(); ++i) {
    if (hard[i] == kHardObject) keep[label[nodes.cell_of_node[i]]] = 1;
  }
  keep[0] = 0;
  for (int64_t cell = 0; cell < static_cast<int64_t>(nodes.rows) * nodes.cols; ++cell) {
    if (data[cell] != 0 && !keep[label[cell]]) data[cell] = 0;
  }
  return mask;
}

}  // namespace

struct SegmentSession::Impl {
  Scan scan;
  SegmentOptions options;
  Nodes nodes;
  double features_s = 0;
  // n-link weights, computed once per step kind when first needed.
  std::unique_ptr<NLinks> depth_links, color_links, rgbd_links;
  // The last cut, kept for refinement.
  Cut last;
  std::vector<uint8_t> last_hard;
  SegmentResult last_result;
  bool ran = false;

  const NLinks& Links(const CutWeights& w, std::unique_ptr<NLinks>* cache, SegmentTimings* t) {
    if (!*cache) {
      Timer timer;
      *cache =
          std::make_unique<NLinks>(ComputeNLinks(nodes, w, options.eight_connected, options.sigma_scale));
      t->features_s += timer.Seconds();
    }
    return **cache;
  }

  std::vector<uint8_t> HardFromStrokes(const cv::Mat& strokes, const std::string& what) const {
    if (strokes.rows != nodes.rows || strokes.cols != nodes.cols || strokes.type() != CV_8U) {
      ThrowInputError(what, "", "",
                      fmt::format("stroke labels must be CV_8U {} x {} (the scan's size), got {} x {}",
                                  nodes.rows, nodes.cols, strokes.rows, strokes.cols));
    }
    std::vector<uint8_t> hard(nodes.num(), kFree);
    const uint8_t* s = strokes.ptr<uint8_t>();
    for (int i = 0; i < nodes.num(); ++i) {
      const uint8_t v = s[nodes.cell_of_node[i]];
      if (v == kStrokeObject)
        hard[i] = kHardObject;
      else if (v == kStrokeBackground)
        hard[i] = kHardBackground;
    }
    return hard;
  }

  // The hard labels of the last graph's nodes: `hard` (per node) mapped to the graph.
  std::vector<uint8_t> LocalHard(const std::vector<uint8_t>& hard) const {
    if (last.node_of_local.empty()) return hard;
    std::vector<uint8_t> local(last.node_of_local.size());
    for (size_t k = 0; k < local.size(); ++k) local[k] = hard[last.node_of_local[k]];
    return local;
  }

  // Whether `mask` (the last cut's) holds a cell on an edge of the last graph's ROI that is not an image
  // edge: then the object may go on beyond the ROI, which was too small.
  bool ReachesRoiEdge(const cv::Mat& mask) const {
    const uint8_t* data = mask.ptr<uint8_t>();
    for (size_t k = 0; k < last.on_roi_edge.size(); ++k) {
      if (last.on_roi_edge[k] && data[nodes.cell_of_node[last.node_of_local[k]]] != 0) return true;
    }
    return false;
  }

  // Sets last's node maps to the valid cells of `roi` (an empty rectangle or the whole image = every node).
  void SetRoi(const cv::Rect& roi) {
    last.node_of_local.clear();
    last.local_of_node.clear();
    last.on_roi_edge.clear();
    if (roi.empty() || roi == cv::Rect(0, 0, nodes.cols, nodes.rows)) return;
    last.local_of_node.assign(nodes.num(), -1);
    for (int row = roi.y; row < roi.y + roi.height; ++row) {
      for (int col = roi.x; col < roi.x + roi.width; ++col) {
        const int32_t i = nodes.node_of_cell[static_cast<int64_t>(row) * nodes.cols + col];
        if (i < 0) continue;
        last.local_of_node[i] = static_cast<int32_t>(last.node_of_local.size());
        last.node_of_local.push_back(i);
        const bool edge = (row == roi.y && row > 0) ||
                          (row == roi.y + roi.height - 1 && row < nodes.rows - 1) ||
                          (col == roi.x && col > 0) || (col == roi.x + roi.width - 1 && col < nodes.cols - 1);
        last.on_roi_edge.push_back(edge ? 1 : 0);
      }
    }
  }

  // One cut with the given weights: models from the hard cells (all of them, also outside the ROI), graph
  // over the valid cells of `roi` (empty = the whole image), max-flow. Keeps the graph in `last`.
  cv::Mat RunCut(const CutWeights& w, const NLinks& links, const std::vector<uint8_t>& hard,
                 SegmentResult* result, const cv::Rect& roi = cv::Rect()) {
    Timer timer;
    SetRoi(roi);
    std::vector<int32_t> object, background;
    for (int i = 0; i < nodes.num(); ++i) {
      if (hard[i] == kHardObject)
        object.push_back(i);
      else if (hard[i] == kHardBackground)
        background.push_back(i);
    }
    const LogDensities logp = ComputeLogDensities(nodes, object, background, options,
                                                  last.node_of_local.empty() ? nullptr : &last.node_of_local);
    result->timings.models_s += timer.Seconds();
    last.hard_cap = 0;
    last.links = &links;
    BuildAndCut(nodes, links, logp, w, LocalHard(hard), &result->timings, &result->flow, &last);
    last_hard = hard;
    return MaskFromCut(nodes, last, hard);
  }

  // Step 3's region of interest around the step-1 object (SegmentOptions::roi_margin_cells); empty = whole.
  cv::Rect Step3Roi(const cv::Mat& step1) const {
    if (options.roi_margin_cells <= 0) return cv::Rect();
    const cv::Rect box = cv::boundingRect(step1);
    if (box.empty()) return cv::Rect();
    const int margin =
        std::max(options.roi_margin_cells,
                 static_cast<int>(std::ceil(options.roi_margin_fraction * std::max(box.width, box.height))));
    const int x0 = std::max(0, box.x - margin), y0 = std::max(0, box.y - margin);
    const int x1 = std::min(nodes.cols, box.x + box.width + margin);
    const int y1 = std::min(nodes.rows, box.y + box.height + margin);
    return cv::Rect(x0, y0, x1 - x0, y1 - y0);
  }

  // Step 2: ring cells whose range differs from every step-1 object cell in their window.
  cv::Mat InferBackground(const cv::Mat& step1) const {
    const int r = options.ring_radius_cells;
    cv::Mat dilated;
    cv::dilate(step1, dilated, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    cv::Mat inferred(nodes.rows, nodes.cols, CV_8U, cv::Scalar(0));
    ParallelFor(nodes.rows, [&](int64_t row) {
      const uint8_t* dil = dilated.ptr<uint8_t>(row);
      const uint8_t* obj = step1.ptr<uint8_t>(row);
      uint8_t* out = inferred.ptr<uint8_t>(row);
      for (int col = 0; col < nodes.cols; ++col) {
        if (dil[col] == 0 || obj[col] != 0) continue;
        const int32_t p = nodes.node_of_cell[row * nodes.cols + col];
        if (p < 0) continue;
        const float range = nodes.raw[p][3];
        float closest = std::numeric_limits<float>::infinity();
        for (int dr = -r; dr <= r; ++dr) {
          const int rr = static_cast<int>(row) + dr;
          if (rr < 0 || rr >= nodes.rows) continue;
          const uint8_t* obj_row = step1.ptr<uint8_t>(rr);
          for (int dc = -r; dc <= r; ++dc) {
            const int cc = col + dc;
            if (cc < 0 || cc >= nodes.cols || obj_row[cc] == 0 || dr * dr + dc * dc > r * r) continue;
            const int32_t q = nodes.node_of_cell[static_cast<int64_t>(rr) * nodes.cols + cc];
            if (q >= 0) closest = std::min(closest, std::abs(range - nodes.raw[q][3]));
          }
        }
        const double threshold = options.ring_depth_threshold_m +
                                 options.ring_depth_threshold_fraction * static_cast<double>(range);
        if (std::isfinite(closest) && closest > threshold) out[col] = 255;
      }
    });
    return inferred;
  }
};

SegmentSession::SegmentSession(const Scan& scan, const SegmentOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  CheckScan(scan);
  Timer timer;
  impl_->scan = scan;
  impl_->options = options;
  impl_->nodes = MakeNodes(scan);
  impl_->features_s = timer.Seconds();
}

SegmentSession::~SegmentSession() = default;
SegmentSession::SegmentSession(SegmentSession&&) noexcept = default;
SegmentSession& SegmentSession::operator=(SegmentSession&&) noexcept = default;

SegmentResult SegmentSession::Run(const cv::Mat& strokes) {
  Impl& s = *impl_;
  Timer total;
  SegmentResult result;
  result.timings.features_s = s.features_s;
  s.features_s = 0;  // counted once
  std::vector<uint8_t> hard = s.HardFromStrokes(strokes, "strokes");
  const bool has_object = std::count(hard.begin(), hard.end(), kHardObject) > 0;
  const bool has_background = std::count(hard.begin(), hard.end(), kHardBackground) > 0;
  if (!has_object) ThrowInputError("strokes", "", "", "no object stroke lies on a cell with a return");
  if (!has_background)
    ThrowInputError("strokes", "", "", "no background stroke lies on a cell with a return");
  const SegmentOptions& o = s.options;
  switch (o.method) {
    case SegmentMethod::kDepth:
      result.mask =
          s.RunCut(o.depth_step, s.Links(o.depth_step, &s.depth_links, &result.timings), hard, &result);
      break;
    case SegmentMethod::kColor:
      result.mask =
          s.RunCut(o.color_step, s.Links(o.color_step, &s.color_links, &result.timings), hard, &result);
      break;
    case SegmentMethod::kRgbd:
      result.mask =
          s.RunCut(o.rgbd_step, s.Links(o.rgbd_step, &s.rgbd_links, &result.timings), hard, &result);
      break;
    case SegmentMethod::kTwoStep: {
      // Step 1: depth-dominant cut.
      result.step1_mask =
          s.RunCut(o.depth_step, s.Links(o.depth_step, &s.depth_links, &result.timings), hard, &result);
      // Step 2: background inference on the ring around it.
      result.inferred_background = s.InferBackground(result.step1_mask);
      // Step 3: colour-dominant cut seeded with step 1's object and the inferred + stroked background.
      std::vector<uint8_t> seeds = hard;
      const uint8_t* step1 = result.step1_mask.ptr<uint8_t>();
      const uint8_t* inferred = result.inferred_background.ptr<uint8_t>();
      for (int i = 0; i < s.nodes.num(); ++i) {
        const int32_t cell = s.nodes.cell_of_node[i];
        if (hard[i] == kHardBackground) continue;  // the user's word wins
        if (step1[cell] != 0)
          seeds[i] = kHardObject;
        else if (inferred[cell] != 0)
          seeds[i] = kHardBackground;
      }
      const NLinks& color_links = s.Links(o.color_step, &s.color_links, &result.timings);
      result.mask = s.RunCut(o.color_step, color_links, seeds, &result, s.Step3Roi(result.step1_mask));
      // The object reached the ROI's edge: the ROI was too small, cut the whole image (the
      // time of both cuts is counted).
      if (s.ReachesRoiEdge(result.mask)) result.mask = s.RunCut(o.color_step, color_links, seeds, &result);
      break;
    }
  }
  result.object_cells = cv::countNonZero(result.mask);
  result.graph_nodes = s.last.num_local(s.nodes.num());
  result.timings.total_s = total.Seconds() + result.timings.features_s;
  s.last_result = result;
  s.ran = true;
  return result;
}

SegmentResult SegmentSession::Refine(const cv::Mat& extra_strokes) {
  Impl& s = *impl_;
  if (!s.ran) throw std::logic_error("SegmentSession::Refine called before Run");
  Timer total;
  const std::vector<uint8_t> extra = s.HardFromStrokes(extra_strokes, "extra strokes");
  SegmentResult result = s.last_result;
  result.timings = SegmentTimings();
  bool any = false, outside = false;
  for (int i = 0; i < s.nodes.num(); ++i) {
    if (extra[i] == kFree || extra[i] == s.last_hard[i]) continue;
    s.last_hard[i] = extra[i];
    any = true;
    if (!s.last.local_of_node.empty() && s.last.local_of_node[i] < 0) outside = true;
  }
  if (outside) {
    // A stroke outside the last cut's region of interest: re-run that cut on the whole
    // image with every hard cell so far.
    result.flow = 0;
    result.mask = s.RunCut(*s.last.weights, *s.last.links, s.last_hard, &result);
    result.object_cells = cv::countNonZero(result.mask);
    result.graph_nodes = s.last.num_local(s.nodes.num());
    result.timings.total_s = total.Seconds();
    s.last_result = result;
    return result;
  }
  Graph& g = *s.last.graph;
  const std::vector<uint8_t> local_hard = s.LocalHard(s.last_hard);
  const int n = static_cast<int>(local_hard.size());
  // New t-link capacities: the models re-learnt from all hard cells (options.refine_relearn_models) or only
  // the new hard cells; the graph gets the differences (BK add_tweights accepts negative changes) and the
  // changed nodes are marked for the tree-reusing max-flow.
  std::vector<float> source_cap = s.last.source_cap, sink_cap = s.last.sink_cap;
  if (any && s.options.refine_relearn_models) {
    Timer models;
    std::vector<int32_t> object, background;
    for (int i = 0; i < s.nodes.num(); ++i) {
      if (s.last_hard[i] == kHardObject)
        object.push_back(i);
      else if (s.last_hard[i] == kHardBackground)
        background.push_back(i);
    }
    const LogDensities logp =
        ComputeLogDensities(s.nodes, object, background, s.options,
                            s.last.node_of_local.empty() ? nullptr : &s.last.node_of_local);
    float hard_cap = s.last.hard_cap;
    TLinkCapacities(logp, *s.last.weights, local_hard, &hard_cap, &source_cap, &sink_cap);
    result.timings.models_s = models.Seconds();
  } else {
    for (int k = 0; k < n; ++k) {
      if (local_hard[k] == kHardObject)
        source_cap[k] = s.last.hard_cap, sink_cap[k] = 0;
      else if (local_hard[k] == kHardBackground)
        source_cap[k] = 0, sink_cap[k] = s.last.hard_cap;
    }
  }
  Timer graph_timer;
  int changed = 0;
  for (int k = 0; k < n; ++k) {
    const float ds = source_cap[k] - s.last.source_cap[k], dt = sink_cap[k] - s.last.sink_cap[k];
    if (ds == 0 && dt == 0) continue;
    g.add_tweights(k, ds, dt);
    g.mark_node(k);
    ++changed;
  }
  s.last.source_cap.swap(source_cap);
  s.last.sink_cap.swap(sink_cap);
  result.timings.graph_s = graph_timer.Seconds();
  Timer timer;
  if (changed > 0) result.flow = g.maxflow(/*reuse_trees=*/true);
  result.timings.maxflow_s = timer.Seconds();
  result.mask = MaskFromCut(s.nodes, s.last, s.last_hard);
  if (s.ReachesRoiEdge(result.mask)) {
    // The refined object reached the ROI's edge: re-run the cut on the whole image.
    result.mask = s.RunCut(*s.last.weights, *s.last.links, s.last_hard, &result);
  }
  result.object_cells = cv::countNonZero(result.mask);
  result.graph_nodes = s.last.num_local(s.nodes.num());
  result.timings.total_s = total.Seconds();
  s.last_result = result;
  return result;
}

SegmentResult SegmentObject(const Scan& scan, const cv::Mat& strokes, const SegmentOptions& options) {
  SegmentSession session(scan, options);
  return session.Run(strokes);
}

MaskScores ScoreMask(const cv::Mat& mask, const cv::Mat& truth, const cv::Mat& domain) {
  LIDARSHOP_CHECK(mask.size() == truth.size() && mask.type() == CV_8U && truth.type() == CV_8U);
  LIDARSHOP_CHECK(domain.empty() || (domain.size() == mask.size() && domain.type() == CV_8U));
  MaskScores s;
  for (int row = 0; row < mask.rows; ++row) {
    const uint8_t* m = mask.ptr<uint8_t>(row);
    const uint8_t* t = truth.ptr<uint8_t>(row);
    const uint8_t* d = domain.empty() ? nullptr : domain.ptr<uint8_t>(row);
    for (int col = 0; col < mask.cols; ++col) {
      if (d != nullptr && d[col] == 0) continue;
      const bool a = m[col] != 0, b = t[col] != 0;
      s.true_positive += a && b;
      s.false_positive += a && !b;
      s.false_negative += !a && b;
    }
  }
  const double tp = double(s.true_positive);
  s.iou =
      tp + s.false_positive + s.false_negative > 0 ? tp / (tp + s.false_positive + s.false_negative) : 1.0;
  s.precision = tp + s.false_positive > 0 ? tp / (tp + s.false_positive) : 1.0;
  s.recall = tp + s.false_negative > 0 ? tp / (tp + s.false_negative) : 1.0;
  return s;
}

namespace {
cv::Mat ColorPicture(const Scan& scan) {
  if (scan.has_color()) return scan.color.clone();
  cv::Mat grey;
  scan.intensity.convertTo(grey, CV_8U, 255.0);
  cv::Mat rgb;
  cv::cvtColor(grey, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}
}  // namespace

cv::Mat GrabCutFromStrokes(const Scan& scan, const cv::Mat& strokes, int iterations,
                           int probable_radius_cells) {
  CheckScan(scan);
  LIDARSHOP_CHECK(strokes.size() == cv::Size(scan.cols, scan.rows) && strokes.type() == CV_8U);
  cv::Mat gc_mask(scan.rows, scan.cols, CV_8U, cv::Scalar(cv::GC_PR_BGD));
  if (probable_radius_cells > 0) {
    cv::Mat object_strokes = strokes == kStrokeObject, near;
    const int k = 2 * probable_radius_cells + 1;
    cv::dilate(object_strokes, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    gc_mask.setTo(cv::GC_PR_FGD, near);
  }
  gc_mask.setTo(cv::GC_BGD, scan.valid == 0);
  gc_mask.setTo(cv::GC_BGD, strokes == kStrokeBackground);
  gc_mask.setTo(cv::GC_FGD, strokes == kStrokeObject);
  cv::Mat image = ColorPicture(scan), bgd_model, fgd_model;
  cv::grabCut(image, gc_mask, cv::Rect(), bgd_model, fgd_model, iterations, cv::GC_INIT_WITH_MASK);
  cv::Mat out = (gc_mask == cv::GC_FGD) | (gc_mask == cv::GC_PR_FGD);
  out.setTo(0, scan.valid == 0);
  return out;
}

cv::Mat SegmentOverlay(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes) {
  CheckScan(scan);
  cv::Mat picture = ColorPicture(scan);
  // Cells without a return in dark blue-grey.
  picture.setTo(cv::Scalar(30, 30, 50), scan.valid == 0);
  if (!mask.empty()) {
    LIDARSHOP_CHECK(mask.size() == picture.size() && mask.type() == CV_8U);
    cv::Mat tinted;
    cv::addWeighted(picture, 0.6, cv::Mat(picture.size(), CV_8UC3, cv::Scalar(255, 220, 0)), 0.4, 0, tinted);
    tinted.copyTo(picture, mask);
    cv::Mat eroded;
    cv::erode(mask, eroded, cv::Mat());
    picture.setTo(cv::Scalar(255, 255, 0), mask & ~eroded);
  }
  if (!strokes.empty()) {
    LIDARSHOP_CHECK(strokes.size() == picture.size() && strokes.type() == CV_8U);
    picture.setTo(cv::Scalar(0, 255, 0), strokes == kStrokeObject);
    picture.setTo(cv::Scalar(255, 0, 0), strokes == kStrokeBackground);
  }
  return picture;
}

}  // namespace lidarshop
