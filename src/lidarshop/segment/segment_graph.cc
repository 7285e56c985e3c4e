#include "lidarshop/segment/segment_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/rgbd_cell.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::segment_internal {
namespace {

void ThrowGraphError(const char* message) { throw std::runtime_error(fmt::format("maxflow: {}", message)); }

}  // namespace

namespace {

inline bool IsNode(const Scan& scan, int row, int col) {
  const float range = scan.range.at<float>(row, col);
  return scan.valid.at<uint8_t>(row, col) != 0 && std::isfinite(range) && range > 0;
}

// At most about this many nodes are sampled for the median of the n-link differences.
constexpr int64_t kMedianSampleNodes = 100000;

}  // namespace

ScanStats ComputeScanStats(const Scan& scan, int row_step) {
  row_step = std::max(1, row_step);
  ScanStats stats;
  // Pass 1: the channels' sums, per row so that the result does not depend on threads.
  struct RowSums {
    double sum[4] = {0, 0, 0, 0}, sum2[4] = {0, 0, 0, 0};
    int64_t count = 0;
    float range_min = std::numeric_limits<float>::max(), range_max = 0;
  };
  std::vector<RowSums> rows(scan.rows);
  ParallelFor(scan.rows, [&](int64_t row) {
    RowSums& out = rows[row];
    if (row % row_step != 0) return;
    for (int col = 0; col < scan.cols; ++col) {
      if (!IsNode(scan, static_cast<int>(row), col)) continue;
      const cv::Vec4f v = RgbdAt(scan, static_cast<int>(row), col);
      for (int c = 0; c < 4; ++c) {
        out.sum[c] += v[c];
        out.sum2[c] += double(v[c]) * v[c];
      }
      out.range_min = std::min(out.range_min, v[3]);
      out.range_max = std::max(out.range_max, v[3]);
      ++out.count;
    }
  });
  double sum[4] = {0, 0, 0, 0}, sum2[4] = {0, 0, 0, 0};
  std::vector<int64_t> first_node(scan.rows + 1, 0);
  stats.range_min = std::numeric_limits<float>::max();
  for (int row = 0; row < scan.rows; ++row) {
    for (int c = 0; c < 4; ++c) sum[c] += rows[row].sum[c], sum2[c] += rows[row].sum2[c];
    stats.range_min = std::min(stats.range_min, rows[row].range_min);
    stats.range_max = std::max(stats.range_max, rows[row].range_max);
    first_node[row + 1] = first_node[row] + rows[row].count;
  }
  const int64_t n = stats.num_valid = first_node[scan.rows];
  if (n == 0) {
    stats.range_min = stats.range_max = 0;
    return stats;
  }
  for (int c = 0; c < 4; ++c) {
    stats.mean[c] = static_cast<float>(sum[c] / n);
    const double var = std::max(0.0, sum2[c] / n - (sum[c] / n) * (sum[c] / n));
    stats.inv_std[c] = var > 1e-12 ? static_cast<float>(1.0 / std::sqrt(var)) : 1.0f;
  }
  // Pass 2: the squared differences of the standardized channels over every link, and the sample.
  const auto standard = [&](int row, int col) {
    const cv::Vec4f v = RgbdAt(scan, row, col);
    cv::Vec4f out;
    for (int c = 0; c < 4; ++c) out[c] = (v[c] - stats.mean[c]) * stats.inv_std[c];
    return out;
  };
  const int64_t stride = std::max<int64_t>(1, n / kMedianSampleNodes);
  struct RowLinks {
    double sum[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
    int64_t count[2] = {0, 0};
    std::vector<std::pair<uint8_t, cv::Vec4f>> sample;
  };
  std::vector<RowLinks> links(scan.rows);
  ParallelFor(scan.rows, [&](int64_t row64) {
    const int row = static_cast<int>(row64);
    RowLinks& out = links[row];
    if (row % row_step != 0) return;
    int64_t node = first_node[row];
    for (int col = 0; col < scan.cols; ++col) {
      if (!IsNode(scan, row, col)) continue;
      const cv::Vec4f p = standard(row, col);
      const bool sampled = node % stride == 0;
      ++node;
      for (int d = 0; d < 4; ++d) {
        const int r2 = row + kDirRow[d], c2 = col + kDirCol[d];
        if (r2 >= scan.rows || c2 < 0 || c2 >= scan.cols || !IsNode(scan, r2, c2)) continue;
        const cv::Vec4f q = standard(r2, c2);
        cv::Vec4f diff;
        for (int c = 0; c < 4; ++c) {
          diff[c] = p[c] - q[c];
          out.sum[d < 2 ? 0 : 1][c] += double(diff[c]) * diff[c];
        }
        ++out.count[d < 2 ? 0 : 1];
        if (sampled) out.sample.emplace_back(static_cast<uint8_t>(d), diff);
      }
    }
  });
  for (const RowLinks& row : links) {
    for (int k = 0; k < 2; ++k) {
      for (int c = 0; c < 4; ++c) stats.link_sum[k][c] += row.sum[k][c];
      stats.link_count[k] += row.count[k];
    }
    stats.sample.insert(stats.sample.end(), row.sample.begin(), row.sample.end());
  }
  return stats;
}

Nodes MakeNodes(const Scan& scan, const ScanStats& stats, const cv::Rect& window, const cv::Mat& include) {
  Nodes nodes;
  nodes.window = window & cv::Rect(0, 0, scan.cols, scan.rows);
  nodes.rows = nodes.window.height;
  nodes.cols = nodes.window.width;
  nodes.scan_cols = scan.cols;
  nodes.range_min = stats.range_min;
  nodes.range_max = stats.range_max;
  nodes.node_of_cell.assign(static_cast<size_t>(nodes.rows) * nodes.cols, -1);
  for (int r = 0; r < nodes.rows; ++r) {
    const int row = nodes.window.y + r;
    const uint8_t* included = include.empty() ? nullptr : include.ptr<uint8_t>(r);
    for (int c = 0; c < nodes.cols; ++c) {
      const int col = nodes.window.x + c;
      if ((included != nullptr && included[c] == 0) || !IsNode(scan, row, col)) continue;
      const int64_t cell = static_cast<int64_t>(r) * nodes.cols + c;
      nodes.node_of_cell[cell] = static_cast<int32_t>(nodes.cell_of_node.size());
      nodes.cell_of_node.push_back(static_cast<int32_t>(cell));
      nodes.raw.push_back(RgbdAt(scan, row, col));
    }
  }
  const int n = nodes.num();
  nodes.standard.resize(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          for (int c = 0; c < 4; ++c)
            nodes.standard[i][c] = (nodes.raw[i][c] - stats.mean[c]) * stats.inv_std[c];
        }
      },
      4096);
  return nodes;
}

NLinks ComputeNLinks(const Nodes& nodes, const ScanStats& stats, const CutWeights& w, bool eight_connected,
                     double sigma_scale) {
  NLinks links;
  links.directions = eight_connected ? 4 : 2;
  const int n = nodes.num();
  const float lambda[4] = {float(w.lambda_r), float(w.lambda_g), float(w.lambda_b), float(w.lambda_d)};
  for (int d = 0; d < links.directions; ++d) links.weight[d].assign(n, -1.0f);
  // Pass 1: weighted squared differences of the window's links.
  ParallelFor(nodes.rows, [&](int64_t row) {
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
      }
    }
  });
  // σ² from the whole scan's links (ScanStats), so that a window sees the σ² of the whole scan.
  const int kinds = eight_connected ? 2 : 1;
  double total = 0;
  int64_t count = 0;
  for (int k = 0; k < kinds; ++k) {
    for (int c = 0; c < 4; ++c) total += lambda[c] * stats.link_sum[k][c];
    count += stats.link_count[k];
  }
  const double mean = count > 0 ? total / count : 0.0;
  double typical = mean;
  if (w.median_sigma && count > 0) {
    std::vector<float> sample;
    for (const auto& [d, diff] : stats.sample) {
      if (d >= links.directions) continue;
      float d2 = 0;
      for (int c = 0; c < 4; ++c) d2 += lambda[c] * diff[c] * diff[c];
      sample.push_back(d2);
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

}  // namespace lidarshop::segment_internal
