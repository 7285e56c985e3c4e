// Cutting an object out of a scan from a few strokes: graph cuts on the RGB+D image (two-step RGB + depth).
//
// The scan is treated as an RGB+D image (scan/scan.h RgbdImage: R, G, B in [0, 1] and range in metres; scans
// without colour use the intensity as grey; scans with neither have constant R, G, B, so only the depth
// separates). Every valid cell is a node of a grid graph; cells without a
// return are NOT nodes (they are never "depth 0"): they have no n-links, are never part of the object and
// split the grid where they lie. The minimum cut comes from the Boykov–Kolmogorov max-flow (Debian
// libmaxflow, the reference implementation).
//
// Energy of a labelling l (1 = object, 0 = background), thesis eqs. 5.6–5.11:
//   E(l) = Σ_p D_p(l_p) + γ Σ_{p~q} w_pq [l_p ≠ l_q]
//   w_pq = exp(−‖I_p − I_q‖² / 2σ²) / dist(p, q),  ‖I_p − I_q‖² = Σ_c λ_c (I_pc − I_qc)²,
// where I_c are the channels R, G, B, range, each standardized over the valid cells of the image (zero mean,
// unit standard deviation), λ_c the per-channel weights and σ² = sigma_scale² · mean over all n-links of
// ‖I_p − I_q‖² (σ estimated from the image; only the ratios of the λ_c matter). dist = 1 for 4-neighbours, √2
// for diagonals. D_p(l) = −α_c log P_l(rgb_p) − α_d log P_l(range_p) (+ a constant foreground bias), with the
// foreground and background models learnt from the stroke cells (histograms or Gaussian mixtures, each mixed
// with a uniform density so that unseen values stay possible; the background model gives the uniform part
// more weight because the background is "everything else"). Stroke cells are hard constraints.
//
// Two-step method (SegmentMethod::kTwoStep):
//   1. depth-dominant cut (λ_d ≫ λ_rgb, plus a foreground bias): a strict subset of the object — sharp
//      where the object stands out in depth, nothing where it meets the ground;
//   2. background inference: dilate the step-1 object by `ring_radius_cells`; a valid ring cell becomes
//      background where its range differs from the nearest step-1 object cell by more than
//      `ring_depth_threshold_m` (+ a fraction of the range), so cells at the ground contact stay undecided;
//   3. colour-dominant cut seeded with the step-1 object (hard object) and the inferred background + the
//      user's background strokes (hard background); models re-learnt from those seeds.
// A scan with neither colour nor intensity (a PCD or E57 of bare points) stops after step 2: the mask is step
// 1's depth cut; kColor then throws InputError (it needs colour or intensity).
// Baselines (single cut, the same machinery): kDepth (step 1's weights alone), kColor (step 3's weights from
// the strokes alone) and kRgbd (standardized λ = 1/3, 1/3, 1/3, 1).
//
// Refinement: SegmentSession keeps the last cut's graph. Refine() with extra strokes turns the stroke cells
// into hard constraints of that graph and re-runs the max-flow reusing the search trees (BK `reuse_trees`),
// so the cost is proportional to the change, not to the image. Models, n-links and the step-1 result stay.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// Stroke label images: CV_8U rows x cols (image orientation), one of these values per cell.
constexpr uint8_t kStrokeNone = 0;
constexpr uint8_t kStrokeObject = 1;
constexpr uint8_t kStrokeBackground = 2;

// Names (util/enum_names.h): "two-step", "depth", "color", "rgbd".
enum class SegmentMethod { kTwoStep, kDepth, kColor, kRgbd };
enum class AppearanceModel { kHistogram, kGmm };  // "histogram", "gmm"
template <>
const EnumInfo& EnumInfoOf<SegmentMethod>();
template <>
const EnumInfo& EnumInfoOf<AppearanceModel>();

// The weights of one graph cut. All dimensionless (the channels are standardized; costs are in nats).
struct CutWeights {
  double lambda_r = 1.0 / 3.0;  // n-link channel weights λ_c (eq. 5.8); only their ratios matter
  double lambda_g = 1.0 / 3.0;
  double lambda_b = 1.0 / 3.0;
  double lambda_d = 1.0;           // range channel
  double smoothness = 20.0;        // γ, the n-link weight relative to the data term
  double color_data_weight = 1.0;  // α_c in D_p = −α_c log P(rgb) − α_d log P(range)
  double depth_data_weight = 1.0;  // α_d
  // Nats added to the object cost of every non-stroke cell (> 0 = conservative).
  double foreground_bias = 0.0;
  // σ² from the median of the n-link ‖ΔI‖² (robust: slopes such as the ground seen at grazing angles count as
  // edges) instead of the mean (GrabCut's β); floored at 1% of the mean.
  bool median_sigma = false;

  void Check() const;  // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<CutWeights>();

struct SegmentOptions {
  SegmentMethod method = SegmentMethod::kTwoStep;
  AppearanceModel model = AppearanceModel::kGmm;  // measured better than histograms (segment.md)
  bool eight_connected = false;  // 8-neighbour n-links (diagonals weighted 1/√2) instead of 4
  double sigma_scale = 1.0;      // σ² = sigma_scale² · mean n-link ‖ΔI‖² (dimensionless, > 0)

  // Step 1 / the "depth" baseline: n-links on the range channel alone (λ_rgb = 0: after standardization over
  // the image, neighbouring range differences are tiny next to colour texture, so any colour weight takes
  // over), a weak colour data term that keeps the cut off ground of another colour, and a foreground bias
  // that keeps it conservative. Tuned on data/segment_eval (bench/results/segment.md).
  CutWeights depth_step = {0.0, 0.0, 0.0, 1.0, 50.0, 0.2, 0.5, 1.5, false};
  // Step 3 / the "color" baseline: colour-dominant n-links, colour data term.
  CutWeights color_step = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.05, 20.0, 1.0, 0.0, 0.0, false};
  // The "rgbd" baseline: one cut with the standardized default weights (eqs. 5.6–5.11).
  CutWeights rgbd_step = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 1.0, 20.0, 1.0, 1.0, 0.0, false};

  // Step 2, background inference.
  int ring_radius_cells = 4;  // dilation radius of the step-1 object, cells (>= 1)
  double ring_depth_threshold_m =
      0.1;  // a ring cell is background when |range − object range| exceeds this ...
  double ring_depth_threshold_fraction = 0.02;  // ... plus this fraction of its range (dimensionless)

  // Step 3 region of interest: the colour-dominant cut only grows the object near the step-1 seed, so its
  // graph covers the bounding box of the step-1 object (and the object strokes) dilated by
  // max(roi_margin_cells, roi_margin_fraction · the box's larger side) on every side, clipped to the image.
  // Cells outside the ROI are background. When the cut's object reaches an ROI edge that is not an image
  // edge, the ROI was too small and the cut is re-run on the whole image (also in Refine(), as is a stroke
  // outside the ROI). roi_margin_cells = 0 = always the whole image.
  int roi_margin_cells = 50;          // cells (>= 0; 0 disables the ROI)
  double roi_margin_fraction = 0.25;  // of the box's larger side (dimensionless, >= 0)

  // Appearance models.
  int color_bins = 16;              // histogram bins per colour channel (2..64)
  double depth_bin_m = 0.05;        // histogram bin width of the range, metres (> 0)
  double depth_smoothing_m = 0.1;   // Gaussian smoothing of the range histogram, metres (>= 0)
  int gmm_components = 5;           // Gaussians per mixture (colour: 3-D full covariance; range: 1-D)
  int gmm_iterations = 10;          // EM iterations
  uint64_t seed = 1;                // k-means++ initialisation of the mixtures
  double object_uniform = 0.01;     // weight of the uniform density in the object model, (0, 1)
  double background_uniform = 0.3;  // weight of the uniform density in the background model, (0, 1)

  // Refine(): re-learn the appearance models from all hard cells (the last cut's seeds + every stroke so far)
  // and update every t-link (true), or only turn the new stroke cells into hard constraints (false, cheaper,
  // but an object stroke on a missed part then adds little more than the stroke itself).
  bool refine_relearn_models = true;

  void Check() const;  // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<SegmentOptions>();

struct SegmentTimings {
  double features_s = 0, models_s = 0, graph_s = 0, maxflow_s = 0, total_s = 0;  // seconds
};

struct SegmentResult {
  cv::Mat mask;                 // CV_8U 255 = object, rows x cols; 0 where invalid
  cv::Mat step1_mask;           // two-step only: the depth-dominant cut, CV_8U 255/0 (else empty)
  cv::Mat inferred_background;  // two-step only: ring cells marked background in step 2, CV_8U 255/0
  int64_t object_cells = 0;
  int64_t graph_nodes = 0;  // nodes of the last cut's graph (two-step: step 3's region of interest)
  double flow = 0;          // value of the last max-flow (the minimum energy, up to constants)
  SegmentTimings timings;
  std::string Summary() const;  // one line
};
template <>
const StructInfo& InfoOf<SegmentTimings>();
template <>
const StructInfo& InfoOf<SegmentResult>();

// A segmentation that keeps its last graph for fast refinement. Build once (features and n-link weights),
// then Run() and any number of Refine() calls. Not thread-safe; the scan's buffers are shared, not copied.
class SegmentSession {
 public:
  SegmentSession(const Scan& scan, const SegmentOptions& options);
  ~SegmentSession();
  SegmentSession(SegmentSession&&) noexcept;
  SegmentSession& operator=(SegmentSession&&) noexcept;

  // Full segmentation from strokes (CV_8U rows x cols, kStroke* values). Throws InputError when the strokes
  // do not have the scan's size or contain no valid object cell or no valid background cell.
  SegmentResult Run(const cv::Mat& strokes);
  // Adds strokes (same format) to the last cut as hard constraints and re-runs its max-flow incrementally.
  // Run() must have been called.
  SegmentResult Refine(const cv::Mat& extra_strokes);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-shot convenience: SegmentSession(scan, options).Run(strokes).
SegmentResult SegmentObject(const Scan& scan, const cv::Mat& strokes, const SegmentOptions& options = {});

// Intersection over union, precision and recall of `mask` against `truth` (both CV_8U, non-zero = true),
// counted over the cells where `domain` is non-zero (e.g. the valid mask; empty = everywhere).
struct MaskScores {
  double iou = 0, precision = 0, recall = 0;
  int64_t true_positive = 0, false_positive = 0, false_negative = 0;
};
MaskScores ScoreMask(const cv::Mat& mask, const cv::Mat& truth, const cv::Mat& domain = cv::Mat());

// OpenCV grabCut initialised from strokes (the peer baseline): object strokes GC_FGD, background strokes and
// cells without a return GC_BGD, everything else GC_PR_BGD except the cells within `probable_radius_cells` of
// an object stroke, which start as GC_PR_FGD (grabCut needs both probable classes to fit its models). Colour
// only (grabCut has no depth). Returns CV_8U 255/0.
cv::Mat GrabCutFromStrokes(const Scan& scan, const cv::Mat& strokes, int iterations = 5,
                           int probable_radius_cells = 0);

// The overlay picture: the scan's colour (or intensity as grey, or plain grey 128), object cells tinted, the mask outline in
// yellow, object strokes green and background strokes red. CV_8UC3 RGB.
cv::Mat SegmentOverlay(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes);

}  // namespace lidarshop
