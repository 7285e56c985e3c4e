// The graph of one cut (segment.h): valid cells as nodes with standardized channels, n-link weights, t-link
// capacities from the appearance models' log densities, the Boykov–Kolmogorov max-flow and the mask it
// gives. Internal to the segment module.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <maxflow/graph.h>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"

namespace lidarshop::segment_internal {

using Graph = maxflow::Graph<float, float, float>;

// What the cut's features are normalized by, over every valid cell of the whole scan (not only the window
// the graph covers), so that a cut in a window sees the same standardized channels, range span and σ² as one
// over the whole scan. One streaming pass over the scan's rows; nothing of the scan's size is allocated.
struct ScanStats {
  int64_t num_valid = 0;               // cells with a return (valid, finite range > 0)
  cv::Vec4f mean, inv_std;             // per channel R, G, B, range (range in metres)
  float range_min = 0, range_max = 0;  // metres
  // Σ over the links of the squared difference of each standardized channel, and the number of links:
  // [0] = right and down neighbours, [1] = the two diagonals.
  double link_sum[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  int64_t link_count[2] = {0, 0};
  // The links of every stride-th node (stride = max(1, num_valid / 100000)), for CutWeights::median_sigma:
  // direction (0..3, kDirRow/kDirCol) and the standardized channel differences.
  std::vector<std::pair<uint8_t, cv::Vec4f>> sample;
};

// row_step > 1: only every row_step-th row (with its links to the next row), for a quick estimate at a fine
// level whose coarse level was cut (coarse_to_fine.h).
ScanStats ComputeScanStats(const Scan& scan, int row_step = 1);

// The valid cells of `window` (a rectangle of the scan) as graph nodes, with their channels standardized by
// `stats`. Cells are counted in the window (row-major, window.width columns); ScanCell() gives the scan's.
struct Nodes {
  int rows = 0, cols = 0;              // the window's size
  cv::Rect window;                     // in the scan
  int scan_cols = 0;                   // columns of the scan
  std::vector<int32_t> node_of_cell;   // rows*cols, -1 = no return
  std::vector<int32_t> cell_of_node;   // #nodes, cell of the window
  std::vector<cv::Vec4f> raw;          // #nodes: R, G, B in [0, 1], range in metres
  std::vector<cv::Vec4f> standard;     // #nodes: the same, standardized over the scan's valid cells
  float range_min = 0, range_max = 0;  // over the scan's valid cells, metres
  int num() const { return static_cast<int>(cell_of_node.size()); }
  // The scan's cell index (row * scan_cols + col) of node i.
  int64_t ScanCell(int32_t i) const {
    const int32_t cell = cell_of_node[i];
    return static_cast<int64_t>(window.y + cell / cols) * scan_cols + window.x + cell % cols;
  }
  // The node of the scan's cell (row, col), -1 when it has no return or lies outside the window.
  int32_t NodeAt(int row, int col) const {
    if (!window.contains(cv::Point(col, row))) return -1;
    return node_of_cell[static_cast<int64_t>(row - window.y) * cols + col - window.x];
  }
};

// `include` (CV_8U of the window's size; empty = every cell): only its non-zero cells become nodes.
Nodes MakeNodes(const Scan& scan, const ScanStats& stats, const cv::Rect& window,
                const cv::Mat& include = cv::Mat());

// Neighbour offsets in the order right, down, down-right, down-left (each edge is stored once, at its
// upper/left end).
constexpr int kDirRow[4] = {0, 1, 1, 1};
constexpr int kDirCol[4] = {1, 0, 1, -1};

// n-link weights of one cut: weight[d][node] for direction d (0 when there is no neighbour), already times γ.
struct NLinks {
  int directions = 2;
  std::vector<float> weight[4];
  double sigma2 = 0;  // the estimated σ² (standardized units)
};

// σ² is estimated from `stats` (the whole scan's links), the weights computed for the window's links.
NLinks ComputeNLinks(const Nodes& nodes, const ScanStats& stats, const CutWeights& w, bool eight_connected,
                     double sigma_scale);

// Log densities of colour (per unit volume of [0,1]^3) and range (per metre) under the object and background
// models (appearance.h), per graph node.
struct LogDensities {
  std::vector<float> color_object, color_background, depth_object, depth_background;  // #nodes
};

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
                     float* hard_cap, std::vector<float>* source_cap, std::vector<float>* sink_cap);

// Builds the graph of one cut and runs the max-flow. `hard` holds kFree / kHardObject / kHardBackground per
// graph node; `cut` comes with node_of_local / local_of_node set (or empty for the whole image), and `logp`
// and `hard` are indexed by graph node. n-links to nodes outside the graph are dropped.
void BuildAndCut(const Nodes& nodes, const NLinks& links, const LogDensities& logp, const CutWeights& w,
                 const std::vector<uint8_t>& hard, SegmentTimings* timings, double* flow, Cut* cut_out);

// Object cells (255) from a cut, keeping only the 4-connected components that contain a kHardObject node of
// `hard` (per node, not per graph node); cells of other components are dropped. The window's size.
cv::Mat MaskFromCut(const Nodes& nodes, const Cut& cut, const std::vector<uint8_t>& hard);

}  // namespace lidarshop::segment_internal
