// Hole filling in organized scans: remove an object, or complete the surface hidden behind it (thesis ch. 6).
//
// A hole is a set of cells of the scan's ray image (CV_8U rows x cols, image orientation, non-zero = fill
// this cell; returns already there are replaced). The default method works in the gradient domain
// (thesis 6.4–6.5):
//   1. range gradients: forward differences of the range image, one-sided (backward) where the forward
//      neighbour is in the hole or has no return, 0 where neither neighbour has a return;
//   2. patch-based inpainting (inpaint/) of a joint image — colour (or intensity), the two range-gradient
//      channels and a has-return channel — the colour leading the choice of patches. Every filled cell
//      records the cell it was copied from; its gradients, colour, intensity, label and whether it has a
//      return are copied from that cell (so sky stays sky behind a lamp post);
//   3. range in the hole from the Poisson equation ∇²r = div G with the copied gradients as guidance G and
//      the known ranges around the hole as Dirichlet boundary (poisson/); cells without a return are no-flux
//      boundaries (edges to them are left out), not zero-range Dirichlet values, and copied depth jumps cut
//      the system (FillOptions::depth_jump_ratio);
//   4. the reconstructed ranges are moved onto the planes seen around the hole where the reconstruction says
//      a cell lies on one (fill/surface_planes.h: the crease hidden behind a car);
//   5. every new point is placed along its own cell's ray (`direction`) at the reconstructed range — never on
//      a height field — and flagged in `synthesized`.
// Baselines in the same code path (the same return decision where they make none of their own):
//   laplace      membrane fill ∇²r = 0 of range, colour and intensity (thesis eq. 6.5);
//   depth-patch  the same patch fill with the range itself in place of its gradients, copied directly (the
//                failure of thesis 6.3: patches from another distance float);
//   telea        OpenCV's fast-marching inpainting (Telea 2004) of the range image and the colours.
// Laplace and Telea decide "has a return" from the nearest known cell.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/fill/facade_lattice.h"
#include "lidarshop/fill/surface_planes.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/inpaint/offset_completion.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

class Progress;

// Names (util/enum_names.h): "gradient", "laplace", "depth-patch", "telea".
enum class FillMethod { kGradient, kLaplace, kDepthPatch, kTelea };
template <>
const EnumInfo& EnumInfoOf<FillMethod>();

// The fill's patch inpainting (gradient and depth-patch methods) as InpaintOptions with the fill's defaults:
// 9 x 9 patches (with 6 channels one AVX-512 row per patch row), PatchMatch, a 50-cell local window and the
// combined acceptance tests. FillOptions::inpaint starts from it.
InpaintOptions FillInpaintDefaults();

// The largest patch radius the fill takes (InpaintOptions allows more), cells.
inline constexpr int kFillMaxPatchRadius = 15;

struct FillOptions {
  FillMethod method = FillMethod::kGradient;
  // Patch fill (gradient and depth-patch): the inpainting of the joint image, nested (the CLI's flags and the
  // flat JSON keys of before stay as aliases: patch_radius, priority, search, search_window_radius =
  // inpaint.local_window_radius, patchmatch_random_samples, patchmatch_iterations, acceptance,
  // acceptance_local_first, seed). The fill reads every field but these, which it decides itself:
  //   search           kExhaustive runs the two-step search with the local window as its first bound (the
  //                    same patches, found sooner); PatchMatch draws random samples over the whole scan plus
  //                    samples near the target (a surface hidden behind a large object is found far away,
  //                    e.g. a facade above a car), and gives way to the exact search by exact_search_max_cost;
  //   channel_weights  must stay empty: the weights are color_weight, gradient_weight and return_weight;
  //   stop_for_review  must stay false (the fill cannot stop half way);
  //   seed             also seeds the facade lattice's and the planes' RANSAC;
  //   acceptance       the patch acceptance tests (inpaint/acceptance.h, thesis 7.1), the combined set by
  //                    default: a patch is copied only when what it brings agrees with the target's known part
  //                    (measured on data/fill_eval: mean range RMSE over the non-planar scenes 24 mm with them,
  //                    195 mm without; bench/results/fill.md); `enabled = false` trusts the best patch
  //                    difference alone. acceptance_local_first: search the local window exhaustively first,
  //                    then the whole scan (true), or offer the configured search's best candidates only.
  InpaintOptions inpaint = FillInpaintDefaults();
  // With PatchMatch: the exact search instead when its cost, hole cells x scan cells, is at most this. A
  // 20,000-cell hole in a 480 x 320 scan (3e9) takes about 0.5 s exact; a 100,000-cell hole in a 1000 x 1000
  // scan (1e11) 8 to 16 s, where PatchMatch takes 1.5 s. Measured on data/fill_eval (bench/results/fill.md):
  // mean range RMSE over the non-planar scenes 24.5 mm exact, 81.0 mm PatchMatch, whose local-first candidates
  // let the ground climb into a facade behind a van. 0 = always PatchMatch.
  double exact_search_max_cost = 1e10;
  // Channel weights of the patch difference. Colour is in grey levels (0..255, or intensity × 255; a scan with
  // neither colour nor intensity has a constant colour channel, so only the range gradients guide); a range
  // gradient g becomes 255 · asinh(g / s) / asinh(1) with s its 90th percentile over the known cells (range
  // channel of depth-patch: s = its 5–95 % spread), linear near 0 and logarithmic for steep ground and jumps.
  double color_weight = 1.0;     // per colour channel (>= 0)
  double gradient_weight = 1.0;  // per range-gradient channel (>= 0)
  double return_weight = 1.0;    // has-return channel, 0 or 255 (>= 0)
  // Gradient method: copy the gradients of the inverse range 1/r instead of the range (patches are still
  // matched on the range gradients). On a plane 1/r is an affine function of the ray direction, so its
  // gradients vary slowly over a surface and a patch taken a few rows away (steep ground near the horizon)
  // still continues it correctly; false = the thesis's range gradients, matched and copied.
  bool inverse_range = true;
  // Gradient method: an edge whose two cells' ranges differ by more than this times the nearer one is a depth
  // discontinuity (a silhouette). Such edges are copied with the gradients and cut out of the Poisson system,
  // so that a wall end and the facade far behind it stay apart instead of being joined by a membrane; a part
  // of the hole cut off from every known range by them is left without a return. 0 = never cut.
  double depth_jump_ratio = 0.05;
  // Gradient method: continue the background only (fill/foreground.h). Objects standing in front of the
  // surface behind them (a person beside the removed one, a bench) that touch the hole are filled with it —
  // their own cells are not written — and no patch copying an object in front of the background is taken:
  // the random scenes' worst fills were a touching person's silhouette copied into the hole.
  bool background_only = true;
  // Telea baseline.
  double telea_radius_cells = 3.0;  // neighbourhood of the fast-marching inpainting, cells (> 0)
  // Patch methods: complete the hole by shifted copies of the scan at its dominant patch offsets
  // (inpaint/offset_completion.h: a facade's window pitch brings whole windows) before the greedy patch fill,
  // which then fills only what no offset could. Opt-in: on data/fill_eval (bench/results/fill.md) it is worse
  // than the default since the facade lattice (mean range RMSE over the non-planar scenes 31.3 mm against
  // 14.2), costs about a second more per scene, and on a small scan its offsets can move the horizon
  // (tests/cli_test.sh's sphere with a 2-cell margin: the ground behind it left without returns).
  bool offset_completion = false;
  // Its parameters; empty channel_weights = the fill's (colour, gradient and has-return weights above).
  OffsetCompletionOptions offsets;
  // Gradient method: the hole cells the patch fill copied from a repeating upright plane (a facade's window
  // rows) are copied instead from the cells one or more pitches or storeys along it (fill/facade_lattice.h),
  // so that a hidden window ends at its sill and a wall stays a wall (data/fill_eval: floating points on the
  // three facade scenes 11.8 / 4.2 / 4.4 % without, 0.41 / 0.15 / 0.34 % with; bench/results/fill.md).
  FacadeLatticeOptions lattice;
  PoissonOptions poisson;   // range reconstruction (and the laplace baseline)
  FillPlaneOptions planes;  // gradient method: reconstructed ranges onto the planes around the hole
  // The window the fill works in, so that its cost follows the hole, not the scan: the hole's bounding box
  // grown by `window_margin` times its larger side (at least `window_min_margin_cells`) on each side, then
  // doubled until it holds `window_min_known_ratio` times as many known returns as the hole has cells. The
  // patch search, the gradient statistics, the planes and the Poisson solve see only the window; the cells
  // outside it are copied. 0 = the whole scan. The margin is wide (512 cells) because sources far from the
  // hole matter: with a margin of 64 cells, 31 of the 100 random scenes of docs/results/random_scenes.md (400 x
  // 300 cells) filled worse (floating points 9.29 -> 9.91 % on the mean); at 512 every scan of up to about
  // 1000 x 1000 cells is filled whole, as before; a 200-cell hole in a 2000 x 2000 scan is filled in a 1224 x
  // 1224 window (docs/fill.md).
  double window_margin = 2.0;           // hole sizes
  int window_min_margin_cells = 512;    // cells
  double window_min_known_ratio = 8.0;  // known returns per hole cell
  void Check() const;                   // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<FillOptions>();

struct FillTimings {
  double gradients_s = 0, inpaint_s = 0, lattice_s = 0, poisson_s = 0, planes_s = 0, placement_s = 0,
         total_s = 0;  // wall seconds
};

struct FillResult {
  Scan scan;  // the input with the hole filled; every cell outside the hole is a bit-exact copy
  // CV_8U rows x cols, 255 = a hole cell that got a (synthesized) return; the same as scan.synthesized there.
  cv::Mat filled;
  int64_t hole_cells = 0;         // non-zero cells of the mask
  int64_t synthesized_cells = 0;  // hole cells given a return
  int64_t no_return_cells = 0;    // hole cells left without a return (sky, beyond range)
  int64_t unanchored_cells = 0;   // cells decided "return" but cut off from every known range (left empty)
  int64_t plane_cells = 0;        // synthesized cells placed on a plane seen around the hole
  int64_t offset_cells = 0;       // hole cells copied by offset completion (FillOptions::offset_completion)
  int64_t lattice_cells = 0;      // hole cells copied along a facade's pitch (FillOptions::lattice)
  // Known cells in front of the background that touch the hole, filled along with it and not written
  // (FillOptions::background_only).
  int64_t front_cells = 0;
  // The repeating facades found, one entry per facade and part of the hole: the pitch along it and the storey
  // height up it, metres (0 = does not repeat that way).
  std::vector<double> lattice_pitches_m, lattice_storeys_m;
  int patches = 0;            // patches copied (patch methods)
  bool exact_search = false;  // the patch search was the exact one (FillOptions::exact_search_max_cost)
  // The window the fill worked in (FillOptions::window_margin): first row and column, rows and columns; the
  // whole scan when not windowed.
  int window_row = 0, window_col = 0, window_rows = 0, window_cols = 0;
  cv::Rect Window() const { return {window_col, window_row, window_cols, window_rows}; }
  int64_t candidates_evaluated = 0;
  // Debug images (patch methods; empty otherwise), CV_32F / CV_32S rows x cols:
  cv::Mat gradient_magnitude_before;  // |∇r| of the input, metres per cell, 0 in the hole
  cv::Mat gradient_magnitude_after;   // |∇r| of the guidance after inpainting
  // CV_32S: patch iteration that filled each cell (0 also for the cells of offset completion), −1 = known.
  cv::Mat fill_order;
  cv::Mat source_cell;  // CV_32SC2: (row, col) each hole cell was copied from, (−1, −1) = known
  FillTimings timings;
  // What looks wrong with the fill, one sentence each (an empty mask: nothing was filled); empty when nothing.
  std::vector<std::string> warnings;
  std::string Summary() const;  // one line
};
template <>
const StructInfo& InfoOf<FillTimings>();
template <>
const StructInfo& InfoOf<FillResult>();

// Fills `hole` in `scan`. Throws InputError when the mask's size differs from the scan's, when the mask
// leaves no known cell with a return, or when the scan has no ray directions (an unorganized cloud).
// An empty mask returns a copy of the scan, with a warning.
FillResult FillScan(const Scan& scan, const cv::Mat& hole, const FillOptions& options = {},
                    Progress* progress = nullptr);

// FillScan without the whole scan in its result, so that what a fill costs follows the hole: `scan` and the
// per-cell images (filled, gradient magnitudes, fill order, source cells) cover the window the fill worked in
// (FillResult::Window()), not the scan; `source_cell` holds the scan's rows and columns. Every number is
// FillScan's, every cell of the window too. An empty mask gives an empty window. A caller that owns the scan
// applies the result with ApplyFill; FillScan is this, then ExpandFill (at 100 M rays that copy, the padding
// and the whole-scan passes took 31 of its 33 s, bench/results/scale.md). Throws as FillScan.
FillResult FillScanWindow(const Scan& scan, const cv::Mat& hole, const FillOptions& options = {},
                          Progress* progress = nullptr);

// Writes a FillScanWindow result into the scan it was computed from (PasteScan of its window): `*scan` then
// equals FillScan's `scan`. Throws std::logic_error when the window does not fit the scan.
void ApplyFill(const FillResult& fill, Scan* scan);

// A FillScanWindow result of `scan` made FillScan's: a copy of the scan with the window applied, the images
// padded (nothing when the window is the whole scan).
void ExpandFill(const Scan& scan, FillResult* fill);

// The per-cell images of a FillScanWindow result brought to the scan's size (rows x cols), with FillScan's
// values outside the window (filled 0, gradients 0, fill order −1, source (−1, −1)); `scan` is left as it is.
// For writers of masks and debug pictures: 21 bytes a cell.
void PadFillImages(int rows, int cols, FillResult* fill);

// The hole grown by `margin_cells` (a disc), e.g. an object mask grown so that mixed pixels at its silhouette
// are filled too. CV_8U 255/0.
cv::Mat GrowHole(const cv::Mat& hole, int margin_cells);
// The same when every cell of the hole lies in `hole_box` (a cut's SegmentResult::object_box): only that box
// grown by the margin is read and written, the rest is a LazyZeros buffer, so a station's object grows at the
// cost of its box.
cv::Mat GrowHole(const cv::Mat& hole, int margin_cells, const cv::Rect& hole_box);

}  // namespace lidarshop
