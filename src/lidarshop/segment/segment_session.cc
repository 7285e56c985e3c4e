// SegmentSession: the two-step method (depth-dominant cut, background inference, colour-dominant cut in a
// region of interest), its single-cut baselines and incremental refinement (segment.h), with the cuts' graphs
// on a window around the strokes that grows while a cut reaches its edge (SegmentOptions::window_margin_cells).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/scan_level.h"
#include "lidarshop/segment/appearance.h"
#include "lidarshop/segment/coarse_to_fine.h"
#include "lidarshop/segment/cut_checks.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_graph.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

using namespace segment_internal;  // NOLINT: the graph and appearance helpers of this module

namespace {

// Refine()'s rule that strokes say only what they say (SegmentOptions::refine_monotone), applied to `mask`
// after a refinement from `previous`: object strokes alone only add, background strokes alone only remove the
// 8-connected parts of the dropped cells that hold one of `background_cells` (scan cells of the new
// background strokes). Mixed strokes keep the new cut.
// `previous_box` and `mask_box` hold every cell of the two masks: on a large station both are a small part of
// the scan, and only they are read and written (a mask read or written whole touches all its memory).
void KeepMonotone(const cv::Mat& previous, const cv::Rect& previous_box, bool object_strokes,
                  bool background_strokes, const std::vector<int64_t>& background_cells,
                  const cv::Rect& mask_box, cv::Mat* mask) {
  if (previous.empty() || object_strokes == background_strokes) return;
  const cv::Rect whole(0, 0, previous.cols, previous.rows);
  const cv::Rect box = previous_box & whole;
  if (object_strokes) {
    if (box.empty()) return;
    cv::Mat in_box = (*mask)(box);
    in_box |= previous(box);
    return;
  }
  // Re-learnt models must not take away object parts elsewhere: the new cut within the previous one.
  const cv::Rect new_box = mask_box & whole;
  for (int row = new_box.y; row < new_box.y + new_box.height; ++row) {
    uint8_t* m = mask->ptr<uint8_t>(row);
    const uint8_t* p = previous.ptr<uint8_t>(row);
    for (int col = new_box.x; col < new_box.x + new_box.width; ++col)
      if (m[col] != 0 && p[col] == 0) m[col] = 0;
  }
  if (box.empty()) return;
  cv::Mat dropped = previous(box) & ~(*mask)(box), part;
  const int count = cv::connectedComponents(dropped, part, 8, CV_32S);
  std::vector<uint8_t> touched(static_cast<size_t>(count), 0);
  for (int64_t cell : background_cells) {
    const int row = static_cast<int>(cell / previous.cols) - box.y;
    const int col = static_cast<int>(cell % previous.cols) - box.x;
    if (row >= 0 && col >= 0 && row < box.height && col < box.width)
      touched[static_cast<size_t>(part.at<int32_t>(row, col))] = 1;
  }
  for (int row = 0; row < box.height; ++row) {
    const int32_t* label = part.ptr<int32_t>(row);
    uint8_t* m = mask->ptr<uint8_t>(box.y + row) + box.x;
    for (int col = 0; col < box.width; ++col)
      if (label[col] != 0 && !touched[static_cast<size_t>(label[col])]) m[col] = 255;
  }
}

// The cells of `box` where `now` holds a stroke that `seen` does not, row by row, into `added`; false when a
// stroke of `seen` is erased or relabelled in `now`. Rows that are equal are skipped whole (memcmp): a stroke
// changes a few rows of a station.
bool StrokesAdded(const cv::Mat& seen, const cv::Mat& now, const cv::Rect& box,
                  std::vector<StrokeCell>* added) {
  constexpr int kRowsPerBlock = 256;
  const int blocks = (box.height + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<std::vector<StrokeCell>> found(static_cast<size_t>(blocks));
  std::atomic<bool> taken_away = false;
  ParallelFor(blocks, [&](int64_t block) {
    const int end = box.y + std::min(box.height, static_cast<int>(block + 1) * kRowsPerBlock);
    for (int row = box.y + static_cast<int>(block) * kRowsPerBlock; row < end && !taken_away; ++row) {
      const uint8_t *was = seen.ptr<uint8_t>(row), *is = now.ptr<uint8_t>(row);
      if (std::memcmp(was + box.x, is + box.x, static_cast<size_t>(box.width)) == 0) continue;
      for (int col = box.x; col < box.x + box.width; ++col) {
        if (is[col] == was[col]) continue;
        if (was[col] != kStrokeNone) {
          taken_away = true;
          break;
        }
        found[static_cast<size_t>(block)].push_back({static_cast<int64_t>(row) * now.cols + col, is[col]});
      }
    }
  });
  if (taken_away) return false;
  added->clear();
  for (const std::vector<StrokeCell>& cells : found) added->insert(added->end(), cells.begin(), cells.end());
  return true;
}

}  // namespace

struct SegmentSession::Impl {
  Scan scan;
  SegmentOptions given;    // as the caller gave them
  SegmentOptions options;  // in force: `given` with the metric lengths scaled to the data at Run()
  ScanStats stats;         // the whole scan's channel statistics, computed once
  Nodes nodes;             // the valid cells of the window the cuts' graphs cover
  int window_growths = 0;  // times the window was grown by the last Run() or Refine()
  // Colour or intensity to tell the object by; without either the colour terms are constant.
  bool has_appearance = false;
  double features_s = 0;
  // n-link weights, computed once per step kind when first needed.
  std::unique_ptr<NLinks> depth_links, color_links, rgbd_links;
  // The last cut, kept for refinement.
  Cut last;
  std::vector<uint8_t> last_hard;
  SegmentResult last_result;
  cv::Mat stroked_part;  // Run(): the part of the step-1 cut the object strokes lie on (cut_checks.h)
  bool ran = false;
  // Coarse to fine (SegmentOptions::coarse_max_cells): the level's factor, session and cells
  // (DecimatedCells).
  int factor = 1;
  std::unique_ptr<SegmentSession> level;
  cv::Mat level_cells;
  // Every stroke so far at full resolution: Run()'s, and the cells with a return of each refinement's. The
  // outline's cut takes them all (coarse to fine); RefineTo() compares with them.
  cv::Mat strokes_so_far;
  cv::Rect strokes_so_far_box;  // every stroke of strokes_so_far lies in it

  // Refine() of a session cut on a level: the strokes `added` at full resolution.
  SegmentResult RefineOnLevel(const std::vector<StrokeCell>& added) {
    Timer total;
    bool object_strokes = false, background_strokes = false;
    std::vector<int64_t> background_cells;
    for (const StrokeCell& stroke : added) {
      if (stroke.label == kStrokeNone || scan.valid.data[stroke.cell] == 0) continue;
      strokes_so_far.data[stroke.cell] = stroke.label;
      strokes_so_far_box |= cv::Rect(static_cast<int>(stroke.cell % scan.cols),
                                     static_cast<int>(stroke.cell / scan.cols), 1, 1);
      if (stroke.label == kStrokeObject) {
        object_strokes = true;
      } else {
        background_strokes = true;
        background_cells.push_back(stroke.cell);
      }
    }
    const SegmentResult at_level = level->Refine(CoarseStrokes(scan, level_cells, added, factor));
    SegmentResult result = FromLevel(at_level, total, 0);
    if (given.refine_monotone) {
      KeepMonotone(last_result.mask, last_result.object_box, object_strokes, background_strokes,
                   background_cells, result.object_box, &result.mask);
      result.object_box |= last_result.object_box;
    }
    result.object_cells = result.object_box.empty() ? 0 : cv::countNonZero(result.mask(result.object_box));
    last_result = result;
    return result;
  }

  // The result at full resolution of the level's cut `at_level`: its outline re-cut (coarse_to_fine.h).
  SegmentResult FromLevel(const SegmentResult& at_level, const Timer& total, double stats_s) const {
    SegmentResult result;
    result.timings = at_level.timings;
    result.mask = CutOutlineAtFullResolution(scan, stats, at_level.mask, level_cells, factor, strokes_so_far,
                                             given, has_appearance, &result);
    if (!at_level.step1_mask.empty())
      result.step1_mask = FullResolutionWithReturns(at_level.step1_mask, factor, scan.valid);
    if (!at_level.inferred_background.empty())
      result.inferred_background =
          FullResolutionWithReturns(at_level.inferred_background, factor, scan.valid);
    if (given.include_enclosed_no_return)
      AddEnclosedNoReturnCells(scan.valid, result.object_box, &result.mask);
    result.object_cells = result.object_box.empty() ? 0 : cv::countNonZero(result.mask(result.object_box));
    result.ray_spacing_m = at_level.ray_spacing_m;
    result.length_scale = at_level.length_scale;
    const cv::Rect window = cv::Rect(at_level.window_col * factor, at_level.window_row * factor,
                                     at_level.window_cols * factor, at_level.window_rows * factor) &
                            WholeScan();
    result.window_row = window.y;
    result.window_col = window.x;
    result.window_rows = window.height;
    result.window_cols = window.width;
    result.window_growths = at_level.window_growths;
    result.coarse_factor = factor * at_level.coarse_factor;
    result.warnings = at_level.warnings;
    result.timings.total_s = total.Seconds() + stats_s;
    return result;
  }

  const NLinks& Links(const CutWeights& w, std::unique_ptr<NLinks>* cache, SegmentTimings* t) {
    if (!*cache) {
      Timer timer;
      *cache = std::make_unique<NLinks>(
          ComputeNLinks(nodes, stats, w, options.eight_connected, options.sigma_scale));
      t->features_s += timer.Seconds();
    }
    return **cache;
  }

  // The n-links of `w`, one of the three weights of `options`.
  const NLinks& LinksFor(const CutWeights* w, SegmentTimings* t) {
    if (w == &options.depth_step) return Links(*w, &depth_links, t);
    if (w == &options.color_step) return Links(*w, &color_links, t);
    return Links(*w, &rgbd_links, t);
  }

  cv::Rect WholeScan() const { return cv::Rect(0, 0, scan.cols, scan.rows); }

  // The graphs' window: the bounding box of the stroke cells grown by window_margin_cells on every side,
  // clipped to the scan (window_margin_cells = 0 or no stroke: the whole scan).
  cv::Rect StrokeWindow(const cv::Mat& strokes) const {
    if (options.window_margin_cells <= 0) return WholeScan();
    const cv::Rect box = cv::boundingRect(strokes != kStrokeNone);
    if (box.empty()) return WholeScan();
    const int m = options.window_margin_cells;
    return cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) & WholeScan();
  }

  // The window doubled: half its larger side (at least the margin) added on every side, clipped to the scan.
  cv::Rect Grown(const cv::Rect& window) const {
    const int m = std::max(options.window_margin_cells, (std::max(window.width, window.height) + 1) / 2);
    return cv::Rect(window.x - m, window.y - m, window.width + 2 * m, window.height + 2 * m) & WholeScan();
  }

  // Whether `mask` (the scan's size) holds a cell on an edge of the window that is not an edge of the scan:
  // the object may go on beyond the window, which is grown.
  bool TouchesWindowEdge(const cv::Mat& mask) const {
    const cv::Rect& w = nodes.window;
    if (w == WholeScan()) return false;
    const auto any = [&](const cv::Rect& line) { return cv::countNonZero(mask(line)) > 0; };
    return (w.y > 0 && any(cv::Rect(w.x, w.y, w.width, 1))) ||
           (w.y + w.height < scan.rows && any(cv::Rect(w.x, w.y + w.height - 1, w.width, 1))) ||
           (w.x > 0 && any(cv::Rect(w.x, w.y, 1, w.height))) ||
           (w.x + w.width < scan.cols && any(cv::Rect(w.x + w.width - 1, w.y, 1, w.height)));
  }

  // Makes `window` the graphs' window: new nodes and n-links; the hard labels so far are carried over (cells
  // outside the old window had none) and the last graph is dropped (its weights are kept for a re-run).
  void SetWindow(const cv::Rect& window, SegmentTimings* t) {
    Timer timer;
    Nodes next = MakeNodes(scan, stats, window);
    if (!last_hard.empty()) {
      std::vector<uint8_t> hard(next.num(), kFree);
      for (int i = 0; i < nodes.num(); ++i) {
        if (last_hard[i] == kFree) continue;
        const int64_t cell = nodes.ScanCell(i);
        const int32_t j = next.NodeAt(static_cast<int>(cell / scan.cols), static_cast<int>(cell % scan.cols));
        if (j >= 0) hard[j] = last_hard[i];
      }
      last_hard.swap(hard);
    }
    nodes = std::move(next);
    depth_links.reset();
    color_links.reset();
    rgbd_links.reset();
    const CutWeights* weights = last.weights;
    last = Cut();
    last.weights = weights;
    t->features_s += timer.Seconds();
  }

  void Report(SegmentResult* result) const {
    result->window_row = nodes.window.y;
    result->window_col = nodes.window.x;
    result->window_rows = nodes.window.height;
    result->window_cols = nodes.window.width;
    result->window_growths = window_growths;
  }

  // Re-runs the last cut on the whole window with every hard cell so far, growing the window while the cut
  // reaches its edge.
  cv::Mat RerunLastCut(SegmentResult* result) {
    result->flow = 0;
    cv::Mat mask = RunCut(*last.weights, LinksFor(last.weights, &result->timings), last_hard, result);
    while (TouchesWindowEdge(mask)) {
      SetWindow(Grown(nodes.window), &result->timings);
      ++window_growths;
      mask = RunCut(*last.weights, LinksFor(last.weights, &result->timings), last_hard, result);
    }
    return mask;
  }

  // A mask of the window's size as a mask of the scan's size (0 outside the window).
  cv::Mat ToScan(const cv::Mat& window_mask) const {
    if (nodes.window == WholeScan()) return window_mask;
    cv::Mat mask = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    window_mask.copyTo(mask(nodes.window));
    return mask;
  }

  std::vector<uint8_t> HardFromStrokes(const cv::Mat& strokes, const std::string& what) const {
    CheckStrokes(strokes, what);
    std::vector<uint8_t> hard(nodes.num(), kFree);
    const uint8_t* s = strokes.ptr<uint8_t>();
    for (int i = 0; i < nodes.num(); ++i) {
      const uint8_t v = s[nodes.ScanCell(i)];
      if (v == kStrokeObject)
        hard[i] = kHardObject;
      else if (v == kStrokeBackground)
        hard[i] = kHardBackground;
    }
    return hard;
  }

  void CheckStrokes(const cv::Mat& strokes, const std::string& what) const {
    if (strokes.rows != scan.rows || strokes.cols != scan.cols || strokes.type() != CV_8U) {
      ThrowInputError(what, "", "",
                      fmt::format("stroke labels must be CV_8U {} x {} (the scan's size), got {} x {}",
                                  scan.rows, scan.cols, strokes.rows, strokes.cols));
    }
  }

  // The hard labels of the last graph's nodes: `hard` (per node) mapped to the graph.
  std::vector<uint8_t> LocalHard(const std::vector<uint8_t>& hard) const {
    if (last.node_of_local.empty()) return hard;
    std::vector<uint8_t> local(last.node_of_local.size());
    for (size_t k = 0; k < local.size(); ++k) local[k] = hard[last.node_of_local[k]];
    return local;
  }

  // Whether `mask` (the last cut's, the scan's size) holds a cell on an edge of the last graph's ROI that is
  // not an edge of the window: then the object may go on beyond the ROI, which was too small.
  bool ReachesRoiEdge(const cv::Mat& mask) const {
    const uint8_t* data = mask.ptr<uint8_t>();
    for (size_t k = 0; k < last.on_roi_edge.size(); ++k) {
      if (last.on_roi_edge[k] && data[nodes.ScanCell(last.node_of_local[k])] != 0) return true;
    }
    return false;
  }

  // Sets last's node maps to the valid cells of `roi` (in the scan) within the window (an empty rectangle or
  // one holding the window = every node).
  void SetRoi(const cv::Rect& roi_in_scan) {
    last.node_of_local.clear();
    last.local_of_node.clear();
    last.on_roi_edge.clear();
    const cv::Rect& w = nodes.window;
    const cv::Rect roi = roi_in_scan & w;
    if (roi_in_scan.empty() || roi == w) return;
    last.local_of_node.assign(nodes.num(), -1);
    for (int row = roi.y; row < roi.y + roi.height; ++row) {
      for (int col = roi.x; col < roi.x + roi.width; ++col) {
        const int32_t i = nodes.NodeAt(row, col);
        if (i < 0) continue;
        last.local_of_node[i] = static_cast<int32_t>(last.node_of_local.size());
        last.node_of_local.push_back(i);
        const bool edge =
            (row == roi.y && row > w.y) || (row == roi.y + roi.height - 1 && row < w.y + w.height - 1) ||
            (col == roi.x && col > w.x) || (col == roi.x + roi.width - 1 && col < w.x + w.width - 1);
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
    return ToScan(MaskFromCut(nodes, last, hard));
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
    const int x1 = std::min(scan.cols, box.x + box.width + margin);
    const int y1 = std::min(scan.rows, box.y + box.height + margin);
    return cv::Rect(x0, y0, x1 - x0, y1 - y0);
  }

  // Step 2: ring cells whose range differs from every step-1 object cell in their window. Read from the scan
  // (not the window's nodes): the same cells whatever the window.
  cv::Mat InferBackground(const cv::Mat& step1) const {
    const int r = options.ring_radius_cells;
    cv::Mat inferred(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
    const cv::Rect box = cv::boundingRect(step1);
    if (box.empty()) return inferred;
    const cv::Rect ring = cv::Rect(box.x - r, box.y - r, box.width + 2 * r, box.height + 2 * r) & WholeScan();
    cv::Mat dilated = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    cv::dilate(step1(ring), dilated(ring),
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)),
               cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    const auto is_node = [&](int row, int col) {
      const float range = scan.range.at<float>(row, col);
      return scan.valid.at<uint8_t>(row, col) != 0 && std::isfinite(range) && range > 0;
    };
    ParallelFor(ring.height, [&](int64_t k) {
      const int row = ring.y + static_cast<int>(k);
      const uint8_t* dil = dilated.ptr<uint8_t>(row);
      const uint8_t* obj = step1.ptr<uint8_t>(row);
      uint8_t* out = inferred.ptr<uint8_t>(row);
      for (int col = ring.x; col < ring.x + ring.width; ++col) {
        if (dil[col] == 0 || obj[col] != 0 || !is_node(row, col)) continue;
        const float range = scan.range.at<float>(row, col);
        float closest = std::numeric_limits<float>::infinity();
        for (int dr = -r; dr <= r; ++dr) {
          const int rr = row + dr;
          if (rr < 0 || rr >= scan.rows) continue;
          const uint8_t* obj_row = step1.ptr<uint8_t>(rr);
          for (int dc = -r; dc <= r; ++dc) {
            const int cc = col + dc;
            if (cc < 0 || cc >= scan.cols || obj_row[cc] == 0 || dr * dr + dc * dc > r * r) continue;
            if (is_node(rr, cc)) closest = std::min(closest, std::abs(range - scan.range.at<float>(rr, cc)));
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
  impl_->given = impl_->options = options;
  impl_->factor = std::min(kMaxLevelStep, CoarseFactor(scan.rows, scan.cols, options.coarse_max_cells));
  if (impl_->factor > 1) {
    // The level is cut by the whole method; here only its outline is, so every 4·f-th row suffices for the
    // standardization and σ² (a 16th of the rows of a 2250 x 3600 station: half a million cells).
    SegmentOptions at_level = options;
    impl_->level_cells = DecimatedCells(scan, impl_->factor);
    impl_->level =
        std::make_unique<SegmentSession>(DecimateScan(scan, impl_->level_cells, impl_->factor), at_level);
    impl_->stats = ComputeScanStats(scan, 4 * impl_->factor);
  } else {
    // The whole scan's statistics once; the nodes of a window at each Run().
    impl_->stats = ComputeScanStats(scan);
  }
  impl_->has_appearance = scan.has_color() || scan.has_intensity();
  impl_->features_s = timer.Seconds();
}

SegmentSession::~SegmentSession() = default;
SegmentSession::SegmentSession(SegmentSession&&) noexcept = default;
SegmentSession& SegmentSession::operator=(SegmentSession&&) noexcept = default;

SegmentResult SegmentSession::Run(const cv::Mat& strokes) {
  Impl& s = *impl_;
  Timer total;
  s.CheckStrokes(strokes, "strokes");
  const double stats_s = s.features_s;  // the constructor's, before this timer
  SegmentTimings timings;
  timings.features_s = s.features_s;
  s.features_s = 0;  // counted once
  s.strokes_so_far = strokes.clone();
  s.strokes_so_far_box = cv::boundingRect(s.strokes_so_far);
  if (s.level) {
    const SegmentResult at_level = s.level->Run(CoarseStrokes(s.scan, s.level_cells, strokes, s.factor));
    s.last_result = s.FromLevel(at_level, total, stats_s);
    s.last_result.timings.features_s += timings.features_s;
    s.ran = true;
    return s.last_result;
  }
  // The graphs cover a window around the strokes, grown while a cut reaches its edge (a cut inside it is the
  // cut of the whole scan: cells outside are background).
  s.options = s.given;
  cv::Rect window = s.StrokeWindow(strokes);
  s.window_growths = 0;
  s.last_hard.clear();
  SegmentResult result;
  std::vector<uint8_t> hard;
  for (;; window = s.Grown(window), ++s.window_growths) {
    if (s.nodes.window != window || s.nodes.cell_of_node.empty()) s.SetWindow(window, &timings);
    result = SegmentResult();
    result.timings = timings;
    bool touched = false;
    hard = s.HardFromStrokes(strokes, "strokes");
    const bool has_object = std::count(hard.begin(), hard.end(), kHardObject) > 0;
    const bool has_background = std::count(hard.begin(), hard.end(), kHardBackground) > 0;
    if (!has_object) ThrowInputError("strokes", "", "", "no object stroke lies on a cell with a return");
    if (!has_background)
      ThrowInputError("strokes", "", "", "no background stroke lies on a cell with a return");
    s.options = s.given;
    if (s.given.scale_to_data) {
      // The object strokes' median range times the ray angle measured around them.
      cv::Mat object_cells = cv::Mat::zeros(s.scan.rows, s.scan.cols, CV_8U);
      std::vector<float> ranges;
      for (int i = 0; i < s.nodes.num(); ++i) {
        if (hard[i] != kHardObject) continue;
        object_cells.data[s.nodes.ScanCell(i)] = 255;
        ranges.push_back(reinterpret_cast<const float*>(s.scan.range.data)[s.nodes.ScanCell(i)]);
      }
      std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
      result.ray_spacing_m = ranges[ranges.size() / 2] * RayAngleAt(s.scan, object_cells);
      if (result.ray_spacing_m > 0) {
        // Scaled down only: a finer scan (a table top at 1 m) resolves depth steps and range bins the outdoor
        // lengths would merge, while a coarser one (a facade at 40 m) keeps them — the range noise of a
        // terrestrial scanner grows far more slowly than the ray spacing (measured: scaling up as well lost the
        // van before its facade, IoU 0.997 -> 0.811).
        result.length_scale = std::min(1.0, result.ray_spacing_m / s.given.reference_spacing_m);
        s.options.depth_bin_m *= result.length_scale;
        s.options.depth_smoothing_m *= result.length_scale;
      }
    }
    const SegmentOptions& o = s.options;
    switch (o.method) {
      case SegmentMethod::kDepth:
        result.mask =
            s.RunCut(o.depth_step, s.Links(o.depth_step, &s.depth_links, &result.timings), hard, &result);
        break;
      case SegmentMethod::kColor:
        if (!s.has_appearance) {
          throw InputError(
              "segment: the color method needs colour or intensity, and the scan has neither; use the depth "
              "or "
              "two-step method");
        }
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
        if ((touched = s.TouchesWindowEdge(result.step1_mask))) break;
        // A neighbour touching the object at the same range joins the depth cut; it is background from here on.
        cv::Mat neighbours;
        cv::Mat object_cells = cv::Mat::zeros(s.scan.rows, s.scan.cols, CV_8U);
        for (int i = 0; i < s.nodes.num(); ++i)
          if (hard[i] == kHardObject) object_cells.data[s.nodes.ScanCell(i)] = 255;
        // A kerb or skirting the depth cut followed out of the picture is not the object either.
        result.step1_mask = TrimStrips(s.scan, result.step1_mask, object_cells, o.whole_object);
        if (o.whole_object.separate_touching) {
          neighbours = TouchingNeighbours(s.scan, result.step1_mask, object_cells, o.whole_object);
          result.step1_mask.setTo(0, neighbours);
        }
        // Step 2: background inference on the ring around it.
        result.inferred_background = s.InferBackground(result.step1_mask);
        if (!neighbours.empty()) result.inferred_background |= neighbours;
        if (!s.has_appearance) {
          // Neither colour nor intensity: step 3 would have nothing to tell the object by and floods the
          // ring. The depth cut is the answer.
          result.mask = result.step1_mask.clone();
          break;
        }
        // Step 3: colour-dominant cut seeded with step 1's object and the inferred + stroked background.
        std::vector<uint8_t> seeds = hard;
        // Step 1's cells on a support plane (ground the depth cut took at the object's foot) are left free.
        cv::Mat step1_seeds = result.step1_mask;
        if (o.whole_object.free_support_seeds)
          step1_seeds = result.step1_mask & ~SupportSurfaceCells(s.scan, result.step1_mask, o.whole_object);
        const uint8_t* step1 = step1_seeds.ptr<uint8_t>();
        const uint8_t* inferred = result.inferred_background.ptr<uint8_t>();
        for (int i = 0; i < s.nodes.num(); ++i) {
          const int64_t cell = s.nodes.ScanCell(i);
          if (hard[i] == kHardBackground) continue;  // the user's word wins
          if (step1[cell] != 0)
            seeds[i] = kHardObject;
          else if (inferred[cell] != 0)
            seeds[i] = kHardBackground;
        }
        const NLinks& color_links = s.Links(o.color_step, &s.color_links, &result.timings);
        result.mask = s.RunCut(o.color_step, color_links, seeds, &result, s.Step3Roi(result.step1_mask));
        // The object reached the ROI's edge: the ROI was too small, cut the whole window (the time of both cuts
        // is counted).
        if (s.ReachesRoiEdge(result.mask)) result.mask = s.RunCut(o.color_step, color_links, seeds, &result);
        if ((touched = s.TouchesWindowEdge(result.mask))) break;
        // (The growth follows the scan's geometry beyond the window as it would over the whole scan.)
        if (o.grow_whole_object) {
          cv::Mat barrier = cv::Mat::zeros(s.scan.rows, s.scan.cols, CV_8U);
          for (int i = 0; i < s.nodes.num(); ++i)
            if (hard[i] == kHardBackground) barrier.data[s.nodes.ScanCell(i)] = 255;
          if (!neighbours.empty()) barrier |= neighbours;
          result.mask = GrowWholeObject(s.scan, result.mask, barrier, o.whole_object);
        }
        // The colour cut and the growth follow such strips too (a kerb's face of the object's orientation).
        result.mask = TrimStrips(s.scan, result.mask, object_cells, o.whole_object);
        break;
      }
    }
    if (o.method != SegmentMethod::kTwoStep) touched = s.TouchesWindowEdge(result.mask);
    timings = result.timings;
    if (!touched) break;
  }
  const SegmentOptions& o = s.options;
  // The part of the object the strokes lie on, which the cut is checked against (and Refine's too).
  s.stroked_part = cv::Mat();
  if (o.method == SegmentMethod::kTwoStep) {
    cv::Mat object_cells = cv::Mat::zeros(s.scan.rows, s.scan.cols, CV_8U);
    for (int i = 0; i < s.nodes.num(); ++i)
      if (hard[i] == kHardObject) object_cells.data[s.nodes.ScanCell(i)] = 255;
    cv::Mat barrier = cv::Mat::zeros(s.scan.rows, s.scan.cols, CV_8U);
    for (int i = 0; i < s.nodes.num(); ++i)
      if (hard[i] == kHardBackground) barrier.data[s.nodes.ScanCell(i)] = 255;
    const cv::Mat stroked = StrokedParts(result.step1_mask, object_cells);
    WholeObjectOptions unbounded = o.whole_object;  // no growth is a leak here: the image bounds it
    unbounded.max_growth = static_cast<double>(s.scan.num_cells()) / std::max(1, cv::countNonZero(stroked));
    s.stroked_part = GrowWholeObject(s.scan, stroked, barrier, unbounded);
    // A cut far larger than that part leaked (the colour cut took a façade or the ground of the object's
    // colour): the part, the object as its geometry outlines it, is the answer.
    const int64_t part_cells = cv::countNonZero(s.stroked_part);
    // (Both checks: a cut far past a small stroked part that stays inside the picture is usually right, the
    // depth cut having found only a piece of the object: a bin at 2 m.)
    if (o.contain_leaks && part_cells > 0 &&
        static_cast<double>(cv::countNonZero(result.mask & ~s.stroked_part)) >
            kCutGrowthLimit * static_cast<double>(part_cells) &&
        CheckCut(result.mask, cv::Mat(), WrapsInAzimuth(s.scan)).size() == 1) {
      result.warnings.push_back(fmt::format(
          "the colour cut took {} cells, far past the {} cells of the part the object strokes lie on: it "
          "leaked, and that part is the cut",
          cv::countNonZero(result.mask), part_cells));
      result.mask = s.stroked_part.clone();
    }
  }
  if (o.include_enclosed_no_return) AddEnclosedNoReturnCells(s.scan.valid, &result.mask);
  result.object_box = s.WholeScan();  // a scan cut whole is small
  result.object_cells = cv::countNonZero(result.mask);
  result.graph_nodes = s.last.num_local(s.nodes.num());
  {
    std::vector<std::string> checks = CheckCut(result.mask, s.stroked_part, WrapsInAzimuth(s.scan));
    result.warnings.insert(result.warnings.end(), checks.begin(), checks.end());
  }
  result.timings.total_s = total.Seconds() + stats_s;
  s.Report(&result);
  s.last_result = result;
  s.ran = true;
  return result;
}

SegmentResult SegmentSession::Refine(const cv::Mat& extra_strokes) {
  Impl& s = *impl_;
  if (!s.ran) throw std::logic_error("SegmentSession::Refine called before Run");
  Timer total;
  s.CheckStrokes(extra_strokes, "extra strokes");
  if (s.level) return s.RefineOnLevel(StrokeCells(extra_strokes));
  {
    const uint8_t* extra = extra_strokes.ptr<uint8_t>();
    const int64_t cells = static_cast<int64_t>(extra_strokes.total());
    for (int64_t cell = 0; cell < cells; ++cell)
      if (extra[cell] != kStrokeNone && s.scan.valid.data[cell] != 0)
        s.strokes_so_far.data[cell] = extra[cell];
    s.strokes_so_far_box |= cv::boundingRect(extra_strokes);
  }
  SegmentResult result = s.last_result;
  result.timings = SegmentTimings();
  s.window_growths = 0;
  bool any = false, outside = false, object_strokes = false, background_strokes = false;
  {
    // Strokes beyond the window: the window takes them in (with the margin) and the last cut is re-run on it.
    const cv::Rect box = cv::boundingRect(extra_strokes != kStrokeNone);
    if (!box.empty() && (box & s.nodes.window) != box) {
      const int m = std::max(0, s.options.window_margin_cells);
      const cv::Rect around(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m);
      s.SetWindow((s.nodes.window | around) & s.WholeScan(), &result.timings);
      ++s.window_growths;
      outside = true;
    }
  }
  const std::vector<uint8_t> extra = s.HardFromStrokes(extra_strokes, "extra strokes");
  for (int i = 0; i < s.nodes.num(); ++i) {
    if (extra[i] == kFree || extra[i] == s.last_hard[i]) continue;
    s.last_hard[i] = extra[i];
    any = true;
    (extra[i] == kHardObject ? object_strokes : background_strokes) = true;
    if (!s.last.local_of_node.empty() && s.last.local_of_node[i] < 0) outside = true;
  }
  const cv::Mat previous_mask = s.last_result.mask;
  const auto keep_monotone = [&](cv::Mat* mask) {
    if (!s.options.refine_monotone) return;
    std::vector<int64_t> background_cells;
    for (int i = 0; i < s.nodes.num(); ++i)
      if (extra[i] == kHardBackground) background_cells.push_back(s.nodes.ScanCell(i));
    KeepMonotone(previous_mask, s.WholeScan(), object_strokes, background_strokes, background_cells,
                 s.WholeScan(), mask);
  };
  if (outside) {
    // A stroke outside the last cut's region of interest or window: re-run that cut on the whole window with
    // every hard cell so far.
    result.mask = s.RerunLastCut(&result);
    keep_monotone(&result.mask);
    if (s.options.include_enclosed_no_return) AddEnclosedNoReturnCells(s.scan.valid, &result.mask);
    result.object_box = s.WholeScan();  // a scan cut whole is small
    result.object_cells = cv::countNonZero(result.mask);
    result.graph_nodes = s.last.num_local(s.nodes.num());
    // New object strokes ask for more object: the growth is the user's, only the borders are checked.
    result.warnings =
        CheckCut(result.mask, object_strokes ? cv::Mat() : s.stroked_part, WrapsInAzimuth(s.scan));
    result.timings.total_s = total.Seconds();
    s.Report(&result);
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
  result.mask = s.ToScan(MaskFromCut(s.nodes, s.last, s.last_hard));
  if (s.ReachesRoiEdge(result.mask) || s.TouchesWindowEdge(result.mask)) {
    // The refined object reached the ROI's or the window's edge: re-run the cut on the whole (grown) window.
    result.mask = s.RerunLastCut(&result);
  }
  keep_monotone(&result.mask);
  if (s.options.include_enclosed_no_return) AddEnclosedNoReturnCells(s.scan.valid, &result.mask);
  result.object_box = s.WholeScan();  // a scan cut whole is small
  result.object_cells = cv::countNonZero(result.mask);
  result.graph_nodes = s.last.num_local(s.nodes.num());
  result.warnings =
      CheckCut(result.mask, object_strokes ? cv::Mat() : s.stroked_part, WrapsInAzimuth(s.scan));
  result.timings.total_s = total.Seconds();
  s.Report(&result);
  s.last_result = result;
  return result;
}

std::optional<SegmentResult> SegmentSession::RefineTo(const cv::Mat& strokes) {
  return RefineTo(strokes, cv::Rect(0, 0, strokes.cols, strokes.rows));
}

std::optional<SegmentResult> SegmentSession::RefineTo(const cv::Mat& strokes, const cv::Rect& strokes_box) {
  Impl& s = *impl_;
  if (!s.ran) return std::nullopt;
  s.CheckStrokes(strokes, "strokes");
  std::vector<StrokeCell> added;
  const cv::Rect compared = (strokes_box | s.strokes_so_far_box) & s.WholeScan();
  if (!StrokesAdded(s.strokes_so_far, strokes, compared, &added)) return std::nullopt;
  if (s.level) return s.RefineOnLevel(added);
  // A scan cut whole is small: its refinement takes the added strokes as an image, those on cells with a
  // return (the only ones Refine() keeps: a stroke on a cell without one stays "added" and is ignored again).
  cv::Mat extra = cv::Mat::zeros(strokes.size(), CV_8U);
  for (const StrokeCell& stroke : added)
    if (s.scan.valid.data[stroke.cell] != 0) extra.data[stroke.cell] = stroke.label;
  return Refine(extra);
}

SegmentResult SegmentObject(const Scan& scan, const cv::Mat& strokes, const SegmentOptions& options) {
  SegmentSession session(scan, options);
  return session.Run(strokes);
}

}  // namespace lidarshop
