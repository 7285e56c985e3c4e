#include "lidarshop/segment/appearance.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Core>

#include "lidarshop/segment/gmm.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop::segment_internal {
namespace {

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

}  // namespace

LogDensities ComputeLogDensities(const Nodes& nodes, const std::vector<int32_t>& object,
                                 const std::vector<int32_t>& background, const SegmentOptions& options,
                                 const std::vector<int32_t>* subset) {
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

}  // namespace lidarshop::segment_internal
