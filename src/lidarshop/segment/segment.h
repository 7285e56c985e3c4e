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
// Window: the graphs cover the strokes' neighbourhood, grown while the cut reaches its edge
// (SegmentOptions::window_margin_cells), so the cost follows the object, not the scan.
//
// Refinement: SegmentSession keeps the last cut's graph. Refine() with extra strokes turns the stroke cells
// into hard constraints of that graph and re-runs the max-flow reusing the search trees (BK `reuse_trees`),
// so the cost is proportional to the change, not to the image. Models, n-links and the step-1 result stay.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/render/strokes.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

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

// Whole-object growth: cells joined to the mask through grid edges that are continuous in depth (a jump under
// jump_cells cell spacings at that range, at least min_jump_m) and in orientation (grid normals within
// max_crease_deg), so parts of another colour join while the support surface, which meets the object at a
// crease, does not. Growth that would add more than max_growth × the object's cells is a leak: none is added.
struct WholeObjectOptions {
  double jump_cells = 6.0;       // depth continuity, in cell spacings at the cell's range (dimensionless)
  double min_jump_m = 0.01;      // floor of the depth-continuity threshold, metres
  double max_crease_deg = 45.0;  // largest angle between neighbouring normals inside one object, degrees
  int normal_window_cells = 2;   // half-width of the grid window of the normals, cells
  double max_growth = 3.0;       // at most this many times the object's cells are added (dimensionless)
  int support_band_cells = 10;   // support planes are fitted to the cells this far around the cut, cells
  // A cell this close to a support plane (and parallel) is support, metres: well above the ground's noise
  // (σ 3 mm along the ray), below the 3 cm of a traffic cone's base plate, which 3 cm took for the ground.
  double support_distance_m = 0.025;
  // ... and "parallel" means a normal within this angle of the plane's, degrees: wide, because the normals of
  // the support's cells along the object's foot mix in the object's side.
  double support_max_tilt_deg = 75.0;
  // Step 3 takes step 1's cells as hard object seeds, except those on a support plane (SupportSurfaceCells):
  // a few ground cells the depth cut took at the object's foot are left to the colour cut instead of being
  // forced into the object.
  bool free_support_seeds = true;
  // Overhangs: a part in front of the object across a depth step, joined to nothing else in depth (every other
  // boundary a step down to something farther or no return), rests on the object and joins it (a mailbox on
  // its post, with the stroke on the post).
  bool join_overhangs = true;
  double overhang_max_contact = 0.5;  // ... and meeting the object along at most this fraction of its outline
  // Parts across a depth step: a part next to the object in the grid behind it across a depth step, its cell
  // there within join_max_gap_m of the object's in space, that is closed (continued in depth and orientation
  // by nothing but the support planes it stands on and creases, within the growth's budget) joins it: the post
  // under a box that overhangs it, table legs under the top. (Not parts in front: a crate before a post's foot
  // occludes it, a lower crate before the box it carries holds it, and one view does not tell them apart.)
  bool join_steps = true;
  double join_max_gap_m = 0.35;  // metres
  // ... and within the part, neighbouring normals may differ by up to this angle, degrees: wider than
  // max_crease_deg, because the grid normals of a thin square post (its corner, its top under the box) turn by
  // more than 45° between neighbouring cells and split it into open pieces (random seeds 12, 43). A closed part
  // cannot leak, and the ground at its foot is kept out by the support planes, not by the crease.
  double join_max_crease_deg = 80.0;
  // Parts it rests on: a closed part in front of the object and below it (joined to nothing else in depth but
  // the support planes it stands on, within the growth's budget) whose top is no higher than
  // support_distance_m above the object's lowest points where they meet joins it: the lower crate of a stack,
  // stroked on the box on top. (A crate before a post's foot hides the foot: the post's lowest visible points
  // lie below the crate's top edge, on the ray that grazes it.)
  bool join_rests_on = true;
  double rests_on_max_growth = 8.0;  // ... up to this many times the object's cells in all (dimensionless)
  // Touching neighbours (TouchingNeighbours): parts of the step-1 cut that the strokes do not touch, cut off
  // from the stroked parts by crevices, are another object at the same range: step 3 takes them as background
  // and the growth does not enter them.
  bool separate_touching = true;
  double crevice_flank_deg = 60.0;       // both flanks of a crevice rise at least this steeply, degrees
  int crevice_baseline_cells = 3;        // the flanks' rise is measured over this many cells
  double neighbour_min_fraction = 0.25;  // smaller parts (× the stroked parts' cells) stay with the object
  // The cuts keep out thin strips along the scene (TrimStrips): the front face of a kerb or a skirting board at
  // the object's range, cut off from the ground above and below by depth steps, joins the depth cut where the
  // object stands by it, and the colour cut and the growth follow it on. 0 = keep them.
  int strip_max_cells = 8;  // rows: the thickest strip dropped (a 0.15 m kerb at 25 m is ~6)
  void Check() const;       // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<WholeObjectOptions>();

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

  // The window the cuts' graphs cover, so that their cost follows the object, not the scan: the bounding box
  // of the stroke cells (object and background) grown by window_margin_cells on every side, clipped to the
  // scan. When a cut (step 1 or step 3; the single cut of the baselines; a refinement's) reaches an edge of
  // the window that is not an edge of the scan, the window is doubled (half its larger side added on every
  // side) and the cut run again, until it does not or the window is the whole scan; a refinement's strokes
  // beyond the window widen it likewise. Cells outside the window are background for the cuts; the
  // whole-object growth, the background inference and the checks read the scan around the cut as they would
  // without a window. The channels' standardization, the range span of the appearance models and σ² are the
  // whole scan's (one streaming pass when the session is made), so a cut that stays inside its window is the
  // cut of the whole scan. 0 = the whole scan.
  int window_margin_cells = 128;  // cells (>= 0)

  // Coarse to fine, so that a cut of a large station costs what its object's outline does: a scan of more
  // cells than this is cut first on a coarser level (DecimateScan, scan/scan_level.h: every f-th ray each way,
  // f the smallest power of two that brings the level to at most this many cells) by the whole method above,
  // with the same options (cell counts are the level's: they were chosen for scans of about this size); its
  // object is taken to full resolution and the cells within two coarse cells of its outline are cut again
  // there (one colour-dominant cut: models from the level's object and its surroundings, every stroke hard).
  // A level is at most 4 times coarser than the scan it comes from; beyond that the level is cut coarse to
  // fine in turn (a pyramid). Refine() refines the level's cut and re-cuts the outline likewise. 0 = always
  // full resolution.
  int coarse_max_cells = 1000000;  // cells (>= 0)

  // Scale to the data: the range-model lengths below (depth_bin_m, depth_smoothing_m) are given for a ray
  // spacing of reference_spacing_m at the object (terrestrial scans of objects metres away) and multiplied by
  // min(1, measured spacing / reference_spacing_m), the spacing being the object strokes' median range ×
  // RayAngleAt the strokes: finer scans (a table top at 1 m) get finer bins, coarser ones keep them. The ring
  // threshold is not scaled: it is the size of a physical step between parts (an overhang), not of the
  // sampling. false = the lengths as given.
  bool scale_to_data = true;
  double reference_spacing_m = 0.0125;  // metres between neighbouring rays the lengths are given for (> 0)

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
  // Refine(): strokes say only what they say. A refinement whose new strokes are all background only removes
  // the parts of the mask its strokes touch (8-connected parts of the dropped cells holding a stroke cell), one
  // whose strokes are all object only adds cells (re-learnt models must not make a correct stroke change the
  // object elsewhere). Mixed strokes take the new cut as is.
  bool refine_monotone = true;
  // Cells without a return enclosed by the object (dark hair, black tyres, windows: no echo, but inside the
  // object's outline) join the mask, so a cut-out has no holes and a fill covers them too.
  bool include_enclosed_no_return = true;
  // Two-step: parts continuous in depth and orientation with the cut join it (GrowWholeObject).
  bool grow_whole_object = true;
  // Two-step: a cut that adds more than kCutGrowthLimit (cut_checks.h) times the part its object strokes lie
  // on beyond it leaked (the colour cut took the façade or the road of the object's colour); that part (step
  // 1's stroked parts grown over depth and orientation, the object as its geometry outlines it) is taken
  // instead, and a warning says so.
  bool contain_leaks = true;
  WholeObjectOptions whole_object;

  void Check() const;  // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<SegmentOptions>();

struct SegmentTimings {
  double features_s = 0, models_s = 0, graph_s = 0, maxflow_s = 0, total_s = 0;  // seconds
};

struct SegmentResult {
  cv::Mat mask;  // CV_8U 255 = object, rows x cols; 0 where invalid unless enclosed (below)
  // Every object cell lies in this box (not always the tightest): what a reader of the mask of a large
  // station needs to look at. Not part of the JSON.
  cv::Rect object_box;
  cv::Mat step1_mask;           // two-step only: the depth-dominant cut, CV_8U 255/0 (else empty)
  cv::Mat inferred_background;  // two-step only: ring cells marked background in step 2, CV_8U 255/0
  int64_t object_cells = 0;
  int64_t graph_nodes = 0;   // nodes of the last cut's graph (two-step: step 3's region of interest)
  double ray_spacing_m = 0;  // measured spacing of neighbouring rays at the object strokes, metres (0: none)
  double length_scale = 1;   // factor applied to the metric lengths (scale_to_data), dimensionless
  double flow = 0;           // value of the last max-flow (the minimum energy, up to constants)
  // The window the cuts' graphs covered (SegmentOptions::window_margin_cells): first row and column, rows and
  // columns (the whole scan when not windowed), and how many times it was grown.
  int window_row = 0, window_col = 0, window_rows = 0, window_cols = 0;
  int window_growths = 0;
  // 1 = cut at full resolution; f > 1 = on the level of every f-th ray, its outline re-cut at full resolution
  // (SegmentOptions::coarse_max_cells; the window is then the level's, in full-resolution cells).
  int coarse_factor = 1;
  SegmentTimings timings;
  // What looks wrong with the cut (segment/cut_checks.h: it grew far past its strokes' part, it touches two
  // borders), one sentence each; empty when nothing does. The mask is kept as it is.
  std::vector<std::string> warnings;
  // Whether extra strokes refined a first cut (SegmentSession::Refine), said by a caller that offers both
  // (segment --refine, the editor's live update); absent (and not in the JSON) otherwise.
  std::optional<bool> refined;
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
  // The live update after a stroke: `strokes` are all the strokes now (same format). When they only add to
  // the strokes of the last Run() and Refine()s — no stroke erased or relabelled — refines the last cut with
  // what they add (Refine); otherwise, or before any Run(), returns nullopt: a full Run() is needed. Rows
  // the strokes leave unchanged are passed over (memcmp); on a level the refinement reads the object's box.
  // The masks of a result are buffers the session does not write again: a caller may keep them without a copy.
  std::optional<SegmentResult> RefineTo(const cv::Mat& strokes);
  // The same when every stroke of `strokes` lies in `strokes_box` (the caller knows where it painted): only
  // that box and the session's own strokes' box are compared, so the cost follows the strokes, not the scan.
  std::optional<SegmentResult> RefineTo(const cv::Mat& strokes, const cv::Rect& strokes_box);

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

cv::Mat GrowWholeObject(const Scan& scan, const cv::Mat& mask, const cv::Mat& barrier,
                        const WholeObjectOptions& options = WholeObjectOptions());

// The cells of `mask` within 4 cells of its outline that lie on a surface the object stands on or against (the
// support planes of GrowWholeObject: the ground, a table, a wall), facing its way: a fringe of support a cut
// took. CV_8U 255/0.
cv::Mat SupportSurfaceCells(const Scan& scan, const cv::Mat& mask,
                            const WholeObjectOptions& options = WholeObjectOptions());

// `mask` (CV_8U: step 1's cut, and the final one) without the thin strips it follows along the scene: the parts
// of at most strip_max_cells rows (a kerb's face, a skirting board, a wall's foot) beyond the box of the rest
// that holds a cell of `object_cells` (the object strokes) are dropped when the mask touches two sides of the
// scan's image (an object lies inside it), or when they lie in the lowest quarter of that box and reach farther
// beyond it on one side than the box is wide (a strip that long along the object's foot runs along the scene;
// a thin part higher up, a table's top seen edge-on, is the object's). The mask as it is otherwise. CV_8U 255/0.
cv::Mat TrimStrips(const Scan& scan, const cv::Mat& mask, const cv::Mat& object_cells,
                   const WholeObjectOptions& options = WholeObjectOptions());

// Crevices between touching bodies in `region` of the scan: grid edges between valid cells where the range
// rises towards the edge from both sides, each flank at least crevice_flank_deg steep (a rise of
// tan(crevice_flank_deg) cell spacings per cell, measured over crevice_baseline_cells). CV_8U of the region's
// size: bit 0 = the edge to the right neighbour, bit 1 = the edge to the neighbour below.
cv::Mat CreviceEdges(const Scan& scan, const cv::Rect& region, const WholeObjectOptions& options);

// The touching neighbours in `mask` (CV_8U): its 4-connected parts, not joined across crevices, that hold no
// cell of `object_cells` (the object strokes) and have at least neighbour_min_fraction × the cells of the parts
// that do. CV_8U 255/0.
cv::Mat TouchingNeighbours(const Scan& scan, const cv::Mat& mask, const cv::Mat& object_cells,
                           const WholeObjectOptions& options = WholeObjectOptions());

// The angle between neighbouring rays near `cells` (CV_8U, rows x cols), radians: the median of the distances
// between the points of neighbouring cells over their range (pairs across depth edges are left out). 0 when no
// pair is found. With a range it gives the scan's own length scale at an object: what "continuous" means there.
double RayAngleAt(const Scan& scan, const cv::Mat& cells);

// Cells without a return (valid == 0) enclosed by `mask`: not reachable from the image border through cells
// outside the mask (4-connected). CV_8U 255/0.
cv::Mat EnclosedNoReturnCells(const cv::Mat& mask, const cv::Mat& valid);
// mask |= EnclosedNoReturnCells(mask, valid), written in place and only within the mask's bounding box.
void AddEnclosedNoReturnCells(const cv::Mat& valid, cv::Mat* mask);
// The same when every cell of the mask lies in `mask_box`: only that box is read.
void AddEnclosedNoReturnCells(const cv::Mat& valid, const cv::Rect& mask_box, cv::Mat* mask);

// The overlay picture: the scan's colour (or intensity as grey, or plain grey 128), object cells tinted and outlined in the
// colour of ContrastingOverlayColor (yellow on most outdoor scenes, another on yellowish ones), object strokes
// green and background strokes red, both widened to OverlayStrokeRadius and rimmed in black. CV_8UC3 RGB.
cv::Mat SegmentOverlay(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes);

// The same overlay on a grid picture of `picture_size` (the scan's grid resampled by nearest neighbour, as
// `render` draws it): object cells tinted, their outline 1 pixel wide, strokes drawn thin — `picture_strokes`
// (stroke labels of picture_size, as painted) when given, else the stroke cells resampled — never widened.
cv::Mat SegmentOverlayPicture(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes,
                              cv::Size picture_size, const cv::Mat& picture_strokes = cv::Mat());

// The overlay of `mask` and the strokes in the layout `render` draws by default (square angular pixels), or
// the layout of the picture the strokes were painted on when it is a grid picture: the scan's colours, object
// cells tinted with a 1-pixel outline, strokes drawn as painted (or their cells resampled), never widened.
// Unorganized clouds (no grid picture): SegmentOverlay's one pixel per cell. CV_8UC3 RGB.
cv::Mat OverlayOnPicture(const Scan& scan, const cv::Mat& mask, const PaintedStrokes& strokes);

// The overlay colour for `picture_rgb` (CV_8UC3): of a fixed list of saturated colours and white (yellow
// first), the first one at least 40 CIELAB units from the colours in `region` (CV_8U; empty = the whole
// picture), else the farthest; distances are taken at the 10th percentile so a few pixels cannot decide.
cv::Vec3b ContrastingOverlayColor(const cv::Mat& picture_rgb, const cv::Mat& region = cv::Mat());

// Radius in pixels of the strokes drawn on an overlay of this size (1 up to 800 pixels across).
int OverlayStrokeRadius(cv::Size picture_size);

}  // namespace lidarshop
