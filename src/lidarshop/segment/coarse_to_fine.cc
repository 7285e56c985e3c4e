#include "lidarshop/segment/coarse_to_fine.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/render/strokes.h"
#include "lidarshop/scan/lazy_zeros.h"
#include "lidarshop/segment/appearance.h"
#include "lidarshop/segment/segment_graph.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::segment_internal {
namespace {

// Model samples are thinned to about this many cells per side, so that fitting the mixtures takes a bounded time.
constexpr size_t kMaxModelSamples = 40000;

cv::Mat Morph(const cv::Mat& mask, int op, int radius) {
  cv::Mat out;
  cv::morphologyEx(mask, out, op,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)),
                   cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

// Every k-th of `cells`, k chosen so that at most kMaxModelSamples remain (deterministic).
std::vector<int32_t> Thinned(std::vector<int32_t> cells) {
  if (cells.size() <= kMaxModelSamples) return cells;
  const size_t step = (cells.size() + kMaxModelSamples - 1) / kMaxModelSamples;
  std::vector<int32_t> out;
  for (size_t i = 0; i < cells.size(); i += step) out.push_back(cells[i]);
  return out;
}

}  // namespace

int CoarseFactor(int rows, int cols, int64_t max_cells) {
  if (max_cells <= 0) return 1;
  int factor = 1;
  const auto cells = [&](int f) {
    return static_cast<int64_t>((rows + f - 1) / f) * static_cast<int64_t>((cols + f - 1) / f);
  };
  while (cells(factor) > max_cells && factor < (1 << 20)) factor *= 2;
  return factor;
}

std::vector<StrokeCell> StrokeCells(const cv::Mat& strokes) {
  std::vector<StrokeCell> cells;
  for (int row = 0; row < strokes.rows; ++row) {
    const uint8_t* s = strokes.ptr<uint8_t>(row);
    for (int col = 0; col < strokes.cols; ++col)
      if (s[col] != kStrokeNone) cells.push_back({static_cast<int64_t>(row) * strokes.cols + col, s[col]});
  }
  return cells;
}

cv::Mat CoarseStrokes(const Scan& scan, const cv::Mat& level_cells, const cv::Mat& strokes, int factor) {
  return CoarseStrokes(scan, level_cells, StrokeCells(strokes), factor);
}

cv::Mat CoarseStrokes(const Scan& scan, const cv::Mat& level_cells, const std::vector<StrokeCell>& cells,
                      int factor) {
  cv::Mat coarse(level_cells.rows, level_cells.cols, CV_8U, cv::Scalar(kStrokeNone));
  const float* range = scan.range.ptr<float>();
  for (const StrokeCell& stroke : cells) {
    if (stroke.label == kStrokeNone || scan.valid.data[stroke.cell] == 0) continue;
    const int row = static_cast<int>(stroke.cell / scan.cols),
              col = static_cast<int>(stroke.cell % scan.cols);
    const int32_t own = level_cells.at<int32_t>(row / factor, col / factor);
    if (scan.valid.data[own] == 0) continue;
    const float r = range[stroke.cell];
    if (std::abs(range[own] - r) > kStrokeSurfaceFraction * r) continue;
    uint8_t& c = coarse.at<uint8_t>(row / factor, col / factor);
    if (c != kStrokeBackground) c = stroke.label;
  }
  return coarse;
}

cv::Mat FullResolution(const cv::Mat& coarse_mask, int factor, cv::Size full) {
  if (coarse_mask.empty()) return cv::Mat();
  cv::Mat up;
  cv::resize(coarse_mask, up, cv::Size(coarse_mask.cols * factor, coarse_mask.rows * factor), 0, 0,
             cv::INTER_NEAREST);
  return up(cv::Rect(0, 0, full.width, full.height)).clone();
}

cv::Mat FullResolutionWithReturns(const cv::Mat& coarse_mask, int factor, const cv::Mat& valid) {
  cv::Mat full = LazyZeros(valid.rows, valid.cols, CV_8U);
  const cv::Rect box = cv::boundingRect(coarse_mask);
  for (int level_row = box.y; level_row < box.y + box.height; ++level_row) {
    const uint8_t* level = coarse_mask.ptr<uint8_t>(level_row);
    for (int row = level_row * factor; row < std::min(valid.rows, (level_row + 1) * factor); ++row) {
      const uint8_t* v = valid.ptr<uint8_t>(row);
      uint8_t* out = full.ptr<uint8_t>(row);
      for (int level_col = box.x; level_col < box.x + box.width; ++level_col) {
        if (level[level_col] == 0) continue;
        for (int col = level_col * factor; col < std::min(valid.cols, (level_col + 1) * factor); ++col)
          if (v[col] != 0) out[col] = level[level_col];
      }
    }
  }
  return full;
}

cv::Mat CutOutlineAtFullResolution(const Scan& scan, const ScanStats& stats, const cv::Mat& coarse_mask,
                                   const cv::Mat& coarse_cells, int factor, const cv::Mat& strokes,
                                   const SegmentOptions& options, bool has_appearance,
                                   SegmentResult* result) {
  Timer timer;
  cv::Mat mask = LazyZeros(scan.rows, scan.cols, CV_8U);  // written in the object's window only
  result->object_box = cv::Rect();
  const cv::Mat object = (coarse_mask != 0);
  if (cv::countNonZero(object) == 0) return mask;
  // On the level: inside (deeper than the band), the band, the graph (the band and one level cell of hard rim
  // on each side) and the surroundings the background model is learnt from.
  const cv::Mat inside = Morph(object, cv::MORPH_ERODE, kBandCoarseCells);
  const cv::Mat outer = Morph(object, cv::MORPH_DILATE, kBandCoarseCells);
  const cv::Mat band = outer & ~inside;
  const cv::Mat graph_cells = Morph(band, cv::MORPH_DILATE, 1);
  const cv::Mat around = Morph(object, cv::MORPH_DILATE, 4 * kBandCoarseCells) & ~outer;
  // Everything below happens in the full-resolution window of the surroundings' box (the band and the
  // graph lie inside it); a level mask there is its blocks' cells.
  const cv::Rect coarse_box = cv::boundingRect(around | object);
  const cv::Rect window = cv::Rect(coarse_box.x * factor, coarse_box.y * factor, coarse_box.width * factor,
                                   coarse_box.height * factor) &
                          cv::Rect(0, 0, scan.cols, scan.rows);
  const auto in_window = [&](const cv::Mat& level_mask) {
    return FullResolution(level_mask(coarse_box), factor, window.size());
  };
  cv::Mat inside_w = in_window(inside), band_w = in_window(band), graph_w = in_window(graph_cells);
  const cv::Mat stroke_w = strokes(window);
  {
    // Strokes the level did not follow (on a part thinner than a level cell, whose block's ray lies on the
    // surface behind it): the cells around them are cut at full resolution too, so that every stroke holds.
    const cv::Mat against = ((stroke_w == kStrokeBackground) & (inside_w != 0)) |
                            ((stroke_w == kStrokeObject) & (inside_w == 0) & (band_w == 0));
    const cv::Rect box = cv::boundingRect(against);
    if (!box.empty()) {
      const int radius = kBandCoarseCells * factor;
      const cv::Rect grown = cv::Rect(box.x - radius - 1, box.y - radius - 1, box.width + 2 * radius + 2,
                                      box.height + 2 * radius + 2) &
                             cv::Rect(0, 0, window.width, window.height);
      const cv::Mat free_cells = Morph(against(grown), cv::MORPH_DILATE, radius);
      cv::Mat band_part = band_w(grown), graph_part = graph_w(grown);
      band_part |= free_cells;
      graph_part |= Morph(free_cells, cv::MORPH_DILATE, 1);
    }
  }
  // Model samples: the level's representatives of the inside and of the surroundings.
  std::vector<int32_t> object_cells, background_cells;
  for (int r = coarse_box.y; r < coarse_box.y + coarse_box.height; ++r) {
    const int32_t* cell = coarse_cells.ptr<int32_t>(r);
    for (int c = coarse_box.x; c < coarse_box.x + coarse_box.width; ++c) {
      if (scan.valid.data[cell[c]] == 0) continue;
      if (inside.at<uint8_t>(r, c) != 0)
        object_cells.push_back(cell[c]);
      else if (around.at<uint8_t>(r, c) != 0)
        background_cells.push_back(cell[c]);
    }
  }
  object_cells = Thinned(std::move(object_cells));
  background_cells = Thinned(std::move(background_cells));
  // The level's band cells hold object cells too (its outline ran through them): without an inside cell (a
  // thin object) its object cells are the samples.
  if (object_cells.empty()) {
    for (int r = coarse_box.y; r < coarse_box.y + coarse_box.height; ++r) {
      const int32_t* cell = coarse_cells.ptr<int32_t>(r);
      for (int c = coarse_box.x; c < coarse_box.x + coarse_box.width; ++c)
        if (object.at<uint8_t>(r, c) != 0 && scan.valid.data[cell[c]] != 0) object_cells.push_back(cell[c]);
    }
  }
  cv::Mat include = graph_w.clone();
  for (const std::vector<int32_t>* cells : {&object_cells, &background_cells}) {
    for (int32_t cell : *cells) {
      const int row = cell / scan.cols - window.y, col = cell % scan.cols - window.x;
      if (row >= 0 && col >= 0 && row < window.height && col < window.width)
        include.at<uint8_t>(row, col) = 1;
    }
  }
  const Nodes nodes = MakeNodes(scan, stats, window, include);
  // Graph nodes: the band and its rim; the rim is hard (inside: object, outside: background), and so is
  // every stroke cell.
  Cut cut;
  cut.local_of_node.assign(nodes.num(), -1);
  std::vector<uint8_t> hard;  // per graph node
  const uint8_t* stroke = strokes.ptr<uint8_t>();
  for (int i = 0; i < nodes.num(); ++i) {
    const int32_t cell = nodes.cell_of_node[i];  // in the window
    if (graph_w.data[cell] == 0) continue;
    cut.local_of_node[i] = static_cast<int32_t>(cut.node_of_local.size());
    cut.node_of_local.push_back(i);
    const uint8_t label = stroke[nodes.ScanCell(i)];
    uint8_t h = kFree;
    if (label == kStrokeObject)
      h = kHardObject;
    else if (label == kStrokeBackground)
      h = kHardBackground;
    else if (band_w.data[cell] == 0)
      h = inside_w.data[cell] != 0 ? kHardObject : kHardBackground;
    hard.push_back(h);
  }
  cut.on_roi_edge.assign(cut.node_of_local.size(), 0);
  std::vector<int32_t> object_nodes, background_nodes;
  const auto to_nodes = [&](const std::vector<int32_t>& cells, std::vector<int32_t>* out) {
    for (int32_t cell : cells) {
      const int32_t i = nodes.NodeAt(cell / scan.cols, cell % scan.cols);
      if (i >= 0) out->push_back(i);
    }
  };
  to_nodes(object_cells, &object_nodes);
  to_nodes(background_cells, &background_nodes);
  const CutWeights& weights = has_appearance ? options.color_step : options.depth_step;
  const NLinks links = ComputeNLinks(nodes, stats, weights, options.eight_connected, options.sigma_scale);
  result->timings.features_s += timer.Seconds();
  timer.Restart();
  const LogDensities logp =
      ComputeLogDensities(nodes, object_nodes, background_nodes, options, &cut.node_of_local);
  result->timings.models_s += timer.Seconds();
  double flow = 0;
  BuildAndCut(nodes, links, logp, weights, hard, &result->timings, &flow, &cut);
  result->flow = flow;
  result->graph_nodes = static_cast<int64_t>(cut.node_of_local.size());
  timer.Restart();
  // The object: inside and not in the band (its cells with a return), and the band's cells the cut gave it.
  cv::Mat object_w = inside_w & (band_w == 0) & (scan.valid(window) != 0);
  for (size_t k = 0; k < cut.node_of_local.size(); ++k) {
    if (cut.graph->what_segment(static_cast<int>(k), Graph::SINK) == Graph::SOURCE)
      object_w.data[nodes.cell_of_node[cut.node_of_local[k]]] = 255;
  }
  // Keep the parts that hold an inside cell or an object stroke.
  cv::Mat labels;
  const int count = cv::connectedComponents(object_w, labels, 4, CV_32S);
  std::vector<uint8_t> keep(static_cast<size_t>(count), 0);
  for (int row = 0; row < window.height; ++row) {
    const uint8_t *o = object_w.ptr<uint8_t>(row), *in = inside_w.ptr<uint8_t>(row),
                  *st = stroke_w.ptr<uint8_t>(row);
    const int32_t* label = labels.ptr<int32_t>(row);
    for (int col = 0; col < window.width; ++col)
      if (o[col] != 0 && (in[col] != 0 || st[col] == kStrokeObject))
        keep[static_cast<size_t>(label[col])] = 1;
  }
  keep[0] = 0;
  for (int row = 0; row < window.height; ++row) {
    uint8_t* o = object_w.ptr<uint8_t>(row);
    const int32_t* label = labels.ptr<int32_t>(row);
    for (int col = 0; col < window.width; ++col)
      if (o[col] != 0 && !keep[static_cast<size_t>(label[col])]) o[col] = 0;
  }
  object_w.copyTo(mask(window));
  result->object_box = window;
  result->timings.graph_s += timer.Seconds();
  return mask;
}

}  // namespace lidarshop::segment_internal
