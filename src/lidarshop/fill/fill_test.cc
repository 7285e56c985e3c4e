#include "lidarshop/fill/fill.h"

#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/range_gradient.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

using fill_internal::EdgeMasks;
using fill_internal::GuidanceDivergence;
using fill_internal::NearestKnownCell;
using fill_internal::NoReturnOnBothSides;
using fill_internal::OneSidedRangeGradient;
using fill_internal::SeamCuts;
using fill_internal::UnanchoredCells;

// A box in front of a wall that meets textured ground: non-planar behind the box. Label 1 = the box.
constexpr const char* kWallScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-20, 20], "elevation_deg": [-20, 10], "columns": 160,
              "rows": 120, "max_range": 40, "los_noise_sigma": 0.002, "seed": 5},
  "objects": [
    {"primitive": "plane", "size": [40, 40], "translate": [0, 15, 0], "label": 0, "texture": "grass"},
    {"primitive": "wall", "size": [12, 0.3, 2.5], "translate": [0, 7, 0], "label": 2, "texture": "brick",
     "color": [158, 68, 48]},
    {"primitive": "box", "size": [0.8, 0.5, 1.2], "translate": [0.2, 4.5, 0.6], "label": 1, "color": [40, 60, 200]}
  ]
})";

// A post against the sky: the top of the hole has nothing behind it.
constexpr const char* kSkyScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-12, 12], "elevation_deg": [-20, 35], "columns": 90,
              "rows": 160, "max_range": 40, "seed": 6},
  "objects": [
    {"primitive": "plane", "size": [40, 40], "translate": [0, 15, 0], "label": 0, "texture": "grass"},
    {"primitive": "cylinder", "radius": 0.12, "height": 5, "translate": [0, 4, 2.5], "label": 1,
     "color": [90, 90, 90]}
  ]
})";

struct FillCase {
  Scan scan, truth;
  cv::Mat hole;
};

FillCase MakeFillCase(const char* json, int margin) {
  const SceneDescription scene = ParseScene(json, "test scene", ".");
  SceneDescription without = scene;
  std::erase_if(without.objects, [](const SceneObject& o) { return o.label == 1; });
  FillCase c{SynthesizeScan(scene), SynthesizeScan(without), {}};
  c.hole = GrowHole((c.scan.label == 1) & (c.scan.valid != 0), margin);
  return c;
}

// The hole grown in its box equals the hole grown whole, also where the grown box reaches the scan's edge.
TEST(GrowHole, InItsBoxEqualsGrowingTheWholeMask) {
  cv::Mat hole = cv::Mat::zeros(40, 50, CV_8U);
  hole(cv::Rect(1, 2, 6, 5)).setTo(255);
  hole(cv::Rect(30, 20, 9, 4)).setTo(255);
  const cv::Rect box = cv::boundingRect(hole);
  for (const int margin : {0, 2, 5}) {
    EXPECT_EQ(cv::countNonZero(GrowHole(hole, margin, box) != GrowHole(hole, margin)), 0) << margin;
  }
  EXPECT_EQ(cv::countNonZero(GrowHole(hole, 3, cv::Rect())), 0);  // an empty box: an empty hole
  EXPECT_THROW(GrowHole(hole, -1, box), OptionsError);
}

TEST(RangeGradient, OneSidedAtTheHoleAndZeroWhereIsolated) {
  // Row 0: 1 2 [hole] 5 ; row 1: 3 4 6 7, all with returns; (0, 3) isolated horizontally and vertically used.
  cv::Mat range = (cv::Mat_<float>(2, 4) << 1, 2, 0, 5, 3, 4, 6, 7.5f);
  cv::Mat usable = (cv::Mat_<uint8_t>(2, 4) << 255, 255, 0, 255, 255, 255, 255, 255);
  const auto g = OneSidedRangeGradient(range, usable);
  EXPECT_FLOAT_EQ(g.gx.at<float>(0, 0), 1.0f);  // forward
  EXPECT_FLOAT_EQ(g.gx.at<float>(0, 1), 1.0f);  // right neighbour in the hole: backward 2 − 1
  EXPECT_FLOAT_EQ(g.gx.at<float>(0, 2), 0.0f);  // the hole itself
  EXPECT_FLOAT_EQ(g.gx.at<float>(0, 3), 0.0f);  // no usable horizontal neighbour
  EXPECT_FLOAT_EQ(g.gx.at<float>(1, 3), 1.5f);  // last column: backward 7.5 − 6
  EXPECT_FLOAT_EQ(g.gy.at<float>(0, 3), 2.5f);  // forward down
  EXPECT_FLOAT_EQ(g.gy.at<float>(1, 0), 2.0f);  // last row: backward 3 − 1
}

TEST(RangeGradient, NearestKnownCellAndUnanchoredParts) {
  cv::Mat hole(5, 5, CV_8U, cv::Scalar(0));
  hole(cv::Rect(1, 1, 3, 3)) = 255;
  const cv::Mat nearest = NearestKnownCell(hole);
  EXPECT_EQ(nearest.at<cv::Vec2i>(1, 1), cv::Vec2i(0, 1));    // first reached from above
  EXPECT_EQ(nearest.at<cv::Vec2i>(0, 0), cv::Vec2i(-1, -1));  // known cells point nowhere
  EXPECT_GE(nearest.at<cv::Vec2i>(2, 2)[0], 0);
  cv::Mat anchor(5, 5, CV_8U, cv::Scalar(0));
  anchor.at<uint8_t>(0, 0) = 255;  // touches nothing of the hole (diagonal only)
  EXPECT_EQ(cv::countNonZero(UnanchoredCells(hole, anchor)), 9);
  anchor.at<uint8_t>(0, 2) = 255;
  EXPECT_EQ(cv::countNonZero(UnanchoredCells(hole, anchor)), 0);
}

TEST(RangeGradient, NoReturnOnBothSidesOfAHoleRun) {
  // Row 0: no return | hole | no return -> marked. Row 1: return on the left -> not. Row 2: the run touches the
  // image's right side -> not.
  cv::Mat hole = cv::Mat::zeros(3, 8, CV_8U), valid = cv::Mat::zeros(3, 8, CV_8U);
  hole.row(0).colRange(2, 5).setTo(255);
  hole.row(1).colRange(2, 5).setTo(255);
  valid.at<uint8_t>(1, 1) = 255;
  hole.row(2).colRange(5, 8).setTo(255);
  const cv::Mat between = NoReturnOnBothSides(hole, valid);
  EXPECT_EQ(cv::countNonZero(between.row(0)), 3);
  EXPECT_EQ(cv::countNonZero(between.row(1)), 0);
  EXPECT_EQ(cv::countNonZero(between.row(2)), 0);

  // Dropouts inside a surface (no-return cells enclosed by returns) do not count; the same row reaching the
  // border through no-return cells does.
  cv::Mat inner_hole = cv::Mat::zeros(3, 16, CV_8U), inner_valid = cv::Mat(3, 16, CV_8U, cv::Scalar(255));
  inner_hole.row(1).colRange(6, 10).setTo(255);
  inner_valid.row(1).colRange(4, 6).setTo(0);
  inner_valid.row(1).colRange(10, 12).setTo(0);
  EXPECT_EQ(cv::countNonZero(NoReturnOnBothSides(inner_hole, inner_valid)), 0);
  inner_valid.row(1).colRange(0, 6).setTo(0);
  inner_valid.row(1).colRange(10, 16).setTo(0);
  EXPECT_EQ(cv::countNonZero(NoReturnOnBothSides(inner_hole, inner_valid)), 4);
}

TEST(RangeGradient, AWallEndTenPercentBeforeTheFacadeIsASilhouetteByDefault) {
  // Row 0: a wall ending at 9 m (cols 0..3) before a facade at 10 m (cols 4..7), 11 % farther; row 1: the
  // facade at a slant, 0.5 % farther per cell. At the old 20 % ratio the wall's end was no jump: copied into a
  // hole, the Poisson system joined the wall to the facade by a membrane (wall_end of the evaluation scenes,
  // 44.6 mm at 20 %, 40.1 mm at 5 %; fill_eval's random seeds 1..100 float 4.06 -> 4.00 %, 101..150
  // 3.77 -> 3.64 %). A surface's own slant between neighbouring cells stays well under the default.
  cv::Mat range(2, 8, CV_32F);
  for (int x = 0; x < 8; ++x) {
    range.at<float>(0, x) = x < 4 ? 9.0f : 10.0f;
    range.at<float>(1, x) = 10.0f * (1.0f + 0.005f * static_cast<float>(x));
  }
  const cv::Mat usable(2, 8, CV_8U, cv::Scalar(255));
  const EdgeMasks jumps = fill_internal::DepthJumps(range, usable, FillOptions{}.depth_jump_ratio);
  EXPECT_TRUE(jumps.right.at<uint8_t>(0, 3));
  EXPECT_EQ(cv::countNonZero(jumps.right), 1);
  EXPECT_EQ(cv::countNonZero(jumps.down.row(0)), 4);  // 9 m over 10.0x m; the facade over itself is none
}

TEST(RangeGradient, SeamsBetweenCopiesAtDifferentDepthsAreCut) {
  // Known: a wall at 5 m (cols 0..3) and a facade at 20 m (cols 4..7) in row 0, the hole in row 1 copies row 0
  // shifted by one column at col 5 (a seam) and unshifted elsewhere.
  cv::Mat range(2, 8, CV_32F, cv::Scalar(0));
  for (int x = 0; x < 8; ++x) range.at<float>(0, x) = x < 4 ? 5.0f : 20.0f;
  cv::Mat hole = cv::Mat::zeros(2, 8, CV_8U);
  hole.row(1).setTo(255);
  cv::Mat source(2, 8, CV_32SC2, cv::Scalar(-1, -1));
  for (int x = 0; x < 8; ++x) source.at<cv::Vec2i>(1, x) = cv::Vec2i(0, x == 5 ? 3 : x);
  EdgeMasks cuts{cv::Mat::zeros(2, 8, CV_8U), cv::Mat::zeros(2, 8, CV_8U)};
  SeamCuts(range, hole, source, 0.2, &cuts);
  // (1,4)-(1,5): shows (0,4) at 20 m and (0,3) at 5 m, not neighbours -> cut; (1,5)-(1,6) likewise.
  EXPECT_TRUE(cuts.right.at<uint8_t>(1, 4));
  EXPECT_TRUE(cuts.right.at<uint8_t>(1, 5));
  // (1,3)-(1,4) shows two neighbouring cells: their own edge decides, not the seam rule.
  EXPECT_FALSE(cuts.right.at<uint8_t>(1, 3));
  // Down edges from the known row: (0,5) at 20 m over (1,5) showing 5 m -> cut; (0,2) over (1,2) showing itself
  // one row up is a copy of the same depth -> not.
  EXPECT_TRUE(cuts.down.at<uint8_t>(0, 5));
  EXPECT_FALSE(cuts.down.at<uint8_t>(0, 2));
  EXPECT_EQ(cv::countNonZero(cuts.right) + cv::countNonZero(cuts.down), 3);
}

TEST(RangeGradient, PoissonWithNoDataCellsReconstructsARampExactly) {
  // A ramp r = 2 + 0.5 x + 0.25 y; the hole is a block; one known cell beside the hole has no data and must
  // not pull the solution (it holds a wrong value on purpose).
  cv::Mat ramp(12, 14, CV_64F);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<double>(y, x) = 2 + 0.5 * x + 0.25 * y;
  cv::Mat hole(ramp.size(), CV_8U, cv::Scalar(0));
  hole(cv::Rect(4, 3, 5, 5)) = 255;
  cv::Mat no_data(ramp.size(), CV_8U, cv::Scalar(0));
  no_data.at<uint8_t>(5, 3) = 255;
  cv::Mat boundary = ramp.clone();
  boundary.setTo(-100.0, no_data);
  cv::Mat gx(ramp.size(), CV_32F, cv::Scalar(0.5f)), gy(ramp.size(), CV_32F, cv::Scalar(0.25f));
  const PoissonSystem system = PreparePoisson(hole, {}, PoissonLinks{no_data, {}, {}});
  const cv::Mat solved = SolvePoisson(system, boundary, GuidanceDivergence(gx, gy, no_data)).image;
  for (int y = 3; y < 8; ++y)
    for (int x = 4; x < 9; ++x)
      EXPECT_NEAR(solved.at<double>(y, x), ramp.at<double>(y, x), 1e-9) << y << "," << x;
  // Without the no-data mask the wrong value leaks in: the test can fail.
  const cv::Mat leaked = SolvePoisson(PreparePoisson(hole), boundary,
                                      GuidanceDivergence(gx, gy, cv::Mat::zeros(ramp.size(), CV_8U)))
                             .image;
  EXPECT_GT(std::abs(leaked.at<double>(5, 4) - ramp.at<double>(5, 4)), 1.0);
}

// The wall scene seen over 160 degrees at the same angular step: the box's hole is a small part of the scan.
std::string WideWallScene() {
  std::string json = kWallScene;
  for (auto [from, to] : {std::pair{R"("azimuth_deg": [-20, 20])", R"("azimuth_deg": [-80, 80])"},
                          std::pair{R"("columns": 160)", R"("columns": 640)"}}) {
    const size_t at = json.find(from);
    if (at == std::string::npos) throw std::logic_error(std::string("kWallScene has no ") + from);
    json.replace(at, std::string(from).size(), to);
  }
  return json;
}

TEST(FillScan, WorksInAWindowAroundTheHoleAsWellAsOnTheWholeScan) {
  const FillCase c = MakeFillCase(WideWallScene().c_str(), 2);
  const int64_t hole_cells = cv::countNonZero(c.hole);
  ASSERT_GT(hole_cells, 500);
  FillOptions options;
  options.window_min_margin_cells = 64;  // the default (512) would take the whole 640-column scan
  const FillResult windowed = FillScan(c.scan, c.hole, options);
  options.window_margin = 0;
  const FillResult whole = FillScan(c.scan, c.hole, options);
  EXPECT_EQ(whole.window_rows, c.scan.rows);
  EXPECT_EQ(whole.window_cols, c.scan.cols);
  // The window holds the hole and its margin, and less than the scan.
  const cv::Rect box = cv::boundingRect(c.hole);
  const cv::Rect window(windowed.window_col, windowed.window_row, windowed.window_cols, windowed.window_rows);
  EXPECT_EQ(window & box, box);
  EXPECT_LT(window.area(), c.scan.rows * c.scan.cols);
  EXPECT_GE(window.x, 0);
  EXPECT_LE(window.x + window.width, c.scan.cols);
  // Outside the hole every cell is the input's; the same cells are filled; the quality is that of the whole
  // scan's fill (the window holds the wall and the ground on both sides of the box).
  const cv::Mat outside = c.hole == 0;
  EXPECT_EQ(cv::norm(windowed.scan.range, c.scan.range, cv::NORM_INF, outside), 0.0);
  EXPECT_EQ(cv::norm(windowed.scan.color, c.scan.color, cv::NORM_INF, outside), 0.0);
  EXPECT_EQ(windowed.hole_cells, hole_cells);
  EXPECT_EQ(cv::countNonZero(windowed.filled), windowed.synthesized_cells);
  EXPECT_EQ(cv::countNonZero(windowed.filled & outside), 0);
  const FillMetrics w = MeasureFill(windowed.scan, c.truth, c.hole);
  const FillMetrics f = MeasureFill(whole.scan, c.truth, c.hole);
  EXPECT_LT(w.range_rmse_mm, 1.25 * f.range_rmse_mm + 5)
      << "window " << w.range_rmse_mm << " whole " << f.range_rmse_mm;
  EXPECT_LT(w.floating_share, f.floating_share + 0.01);
  // Every source cell of the windowed fill is a known cell of the whole scan, inside the window.
  int sources = 0;
  for (int y = 0; y < c.scan.rows; ++y) {
    for (int x = 0; x < c.scan.cols; ++x) {
      const cv::Vec2i source = windowed.source_cell.at<cv::Vec2i>(y, x);
      if (source[0] < 0) continue;
      ++sources;
      EXPECT_TRUE(window.contains(cv::Point(source[1], source[0]))) << source;
    }
  }
  EXPECT_GT(sources, 0);
}

TEST(FillScanWindow, HoldsTheWindowOnlyAndAppliedEqualsFillScan) {
  const FillCase c = MakeFillCase(WideWallScene().c_str(), 2);
  FillOptions options;
  options.window_min_margin_cells = 64;
  const FillResult whole = FillScan(c.scan, c.hole, options);
  FillResult windowed = FillScanWindow(c.scan, c.hole, options);
  const cv::Rect window = windowed.Window();
  ASSERT_EQ(window, whole.Window());
  ASSERT_LT(window.area(), c.scan.rows * c.scan.cols);
  // Everything per cell covers the window, not the scan.
  EXPECT_EQ(windowed.scan.rows, window.height);
  EXPECT_EQ(windowed.scan.cols, window.width);
  for (const cv::Mat* image :
       {&windowed.filled, &windowed.gradient_magnitude_before, &windowed.gradient_magnitude_after,
        &windowed.fill_order, &windowed.source_cell})
    EXPECT_EQ(image->size(), window.size());
  EXPECT_EQ(windowed.synthesized_cells, whole.synthesized_cells);
  EXPECT_EQ(windowed.patches, whole.patches);
  // Applied to a copy of the input it is FillScan's scan, channel by channel.
  Scan applied = Clone(c.scan);
  ApplyFill(windowed, &applied);
  auto same = [](const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() &&
           (a.empty() || cv::norm(a.reshape(1), b.reshape(1), cv::NORM_INF) == 0.0);
  };
  EXPECT_TRUE(same(applied.range, whole.scan.range));
  EXPECT_TRUE(same(applied.point, whole.scan.point));
  EXPECT_TRUE(same(applied.valid, whole.scan.valid));
  EXPECT_TRUE(same(applied.color, whole.scan.color));
  EXPECT_TRUE(same(applied.label, whole.scan.label));
  EXPECT_TRUE(same(applied.synthesized, whole.scan.synthesized));
  EXPECT_TRUE(same(applied.direction, whole.scan.direction));
  // Not through FillScan: the window's cells are the fill of a copy of the window (CropScan, not the view), the
  // cells outside it the input's, and the source cells the window's plus its corner.
  FillOptions in_window = options;
  in_window.window_margin = 0;
  const FillResult cropped = FillScan(CropScan(c.scan, window), c.hole(window), in_window);
  EXPECT_EQ(cv::norm(windowed.scan.range, cropped.scan.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(applied.range(window), cropped.scan.range, cv::NORM_INF), 0.0);
  cv::Mat outside_window(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(255));
  outside_window(window).setTo(0);
  EXPECT_EQ(cv::norm(applied.range, c.scan.range, cv::NORM_INF, outside_window), 0.0);
  int differing_sources = 0;
  for (int y = 0; y < window.height; ++y) {
    for (int x = 0; x < window.width; ++x) {
      cv::Vec2i expected = cropped.source_cell.at<cv::Vec2i>(y, x);
      if (expected[0] >= 0) expected += cv::Vec2i(window.y, window.x);
      differing_sources += windowed.source_cell.at<cv::Vec2i>(y, x) != expected;
    }
  }
  EXPECT_EQ(differing_sources, 0);
  // Padded, the images are FillScan's (source cells in the scan's rows and columns in both).
  PadFillImages(c.scan.rows, c.scan.cols, &windowed);
  EXPECT_EQ(cv::countNonZero(windowed.filled & outside_window), 0);
  EXPECT_EQ(cv::countNonZero((windowed.fill_order != -1) & outside_window), 0);
  EXPECT_TRUE(same(windowed.filled, whole.filled));
  EXPECT_TRUE(same(windowed.fill_order, whole.fill_order));
  EXPECT_TRUE(same(windowed.source_cell, whole.source_cell));
  EXPECT_TRUE(same(windowed.gradient_magnitude_after, whole.gradient_magnitude_after));
}

TEST(FillScanWindow, AHoleCellWithoutADirectionIsNamedInTheScansRowsAndColumns) {
  const FillCase c = MakeFillCase(WideWallScene().c_str(), 2);
  FillOptions options;
  options.window_min_margin_cells = 64;
  const cv::Rect window = FillScanWindow(c.scan, c.hole, options).Window();
  ASSERT_LT(window.area(), c.scan.rows * c.scan.cols);
  ASSERT_GT(window.x, 0);  // so that the window's own columns would name another cell
  cv::Point cell;
  cv::minMaxLoc(c.hole, nullptr, nullptr, nullptr, &cell);  // the first hole cell
  Scan broken = Clone(c.scan);
  broken.direction.at<cv::Vec3f>(cell) = cv::Vec3f(0, 0, 0);
  try {
    FillScanWindow(broken, c.hole, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(fmt::format("(row {}, col {})", cell.y, cell.x)),
              std::string::npos)
        << error.what();
  }
}

TEST(FillScanWindow, AnEmptyMaskGivesAnEmptyWindowThatChangesNothing) {
  const FillCase c = MakeFillCase(WideWallScene().c_str(), 2);
  const cv::Mat nothing = cv::Mat::zeros(c.scan.rows, c.scan.cols, CV_8U);
  FillResult result = FillScanWindow(c.scan, nothing);
  EXPECT_EQ(result.Window().area(), 0);
  EXPECT_EQ(result.hole_cells, 0);
  ASSERT_EQ(result.warnings.size(), 1u);
  Scan applied = Clone(c.scan);
  ApplyFill(result, &applied);
  EXPECT_EQ(cv::norm(applied.range, c.scan.range, cv::NORM_INF), 0.0);
  EXPECT_TRUE(applied.synthesized.empty());
  PadFillImages(c.scan.rows, c.scan.cols, &result);
  ASSERT_EQ(result.filled.size(), c.scan.range.size());
  EXPECT_EQ(cv::countNonZero(result.filled), 0);
  // FillScan of the same mask: a copy of the scan, nothing filled.
  const FillResult copy = FillScan(c.scan, nothing);
  EXPECT_EQ(cv::countNonZero(copy.filled), 0);
  EXPECT_EQ(cv::norm(copy.scan.range, c.scan.range, cv::NORM_INF), 0.0);
}

TEST(FillScan, TheWindowGrowsUntilItHoldsEnoughKnownReturns) {
  const FillCase c = MakeFillCase(WideWallScene().c_str(), 2);
  FillOptions options;
  options.window_min_margin_cells = 64;
  options.window_min_known_ratio = 1e5;  // more than the whole scan holds: the window becomes the scan
  const FillResult result = FillScan(c.scan, c.hole, options);
  EXPECT_EQ(result.window_rows, c.scan.rows);
  EXPECT_EQ(result.window_cols, c.scan.cols);
}

TEST(FillScan, GradientFillBeatsTheMembraneBehindABoxAndKeepsEverythingElse) {
  const FillCase c = MakeFillCase(kWallScene, 2);
  ASSERT_GT(cv::countNonZero(c.hole), 500);
  FillOptions options;
  const FillResult gradient = FillScan(c.scan, c.hole, options);
  options.method = FillMethod::kLaplace;
  const FillResult laplace = FillScan(c.scan, c.hole, options);
  const FillMetrics g = MeasureFill(gradient.scan, c.truth, c.hole);
  const FillMetrics l = MeasureFill(laplace.scan, c.truth, c.hole);
  EXPECT_LT(g.range_rmse_mm, l.range_rmse_mm)
      << "gradient " << g.range_rmse_mm << " laplace " << l.range_rmse_mm;
  // Few floating points (1.3 % measured with the acceptance tests on, 0 without; the membrane floats 30 %+).
  EXPECT_LT(g.floating_share, 0.02);
  EXPECT_LT(g.floating_share, l.floating_share / 4);
  EXPECT_GT(g.return_accuracy, 0.97);
  // The floating-cell map is the share's cells, inside the hole only.
  EXPECT_EQ(cv::countNonZero(l.floating_cells),
            std::lround(l.floating_share * static_cast<double>(laplace.synthesized_cells)));
  EXPECT_GT(cv::countNonZero(l.floating_cells), 0);
  EXPECT_EQ(cv::countNonZero(l.floating_cells & (c.hole == 0)), 0);

  // Outside the hole: a bit-exact copy of every channel.
  const cv::Mat outside = c.hole == 0;
  auto changed_outside = [&](const cv::Mat& a, const cv::Mat& b) {
    std::vector<cv::Mat> pa, pb;
    cv::split(a, pa);
    cv::split(b, pb);
    int count = 0;
    for (size_t k = 0; k < pa.size(); ++k) count += cv::countNonZero((pa[k] != pb[k]) & outside);
    return count;
  };
  EXPECT_EQ(changed_outside(gradient.scan.range, c.scan.range), 0);
  EXPECT_EQ(changed_outside(gradient.scan.point, c.scan.point), 0);
  EXPECT_EQ(changed_outside(gradient.scan.color, c.scan.color), 0);
  EXPECT_EQ(changed_outside(gradient.scan.intensity, c.scan.intensity), 0);
  EXPECT_EQ(changed_outside(gradient.scan.valid, c.scan.valid), 0);

  // Filled cells: flagged, on their own rays at the reconstructed range.
  int checked = 0;
  for (int y = 0; y < c.scan.rows; ++y) {
    for (int x = 0; x < c.scan.cols; ++x) {
      if (!c.hole.at<uint8_t>(y, x)) continue;
      const bool valid = gradient.scan.valid.at<uint8_t>(y, x) != 0;
      EXPECT_EQ(gradient.scan.synthesized.at<uint8_t>(y, x) != 0, valid);
      if (!valid) continue;
      const cv::Vec3f p = gradient.scan.point.at<cv::Vec3f>(y, x);
      const cv::Vec3f d = c.scan.direction.at<cv::Vec3f>(y, x);
      const float r = gradient.scan.range.at<float>(y, x);
      EXPECT_LT(cv::norm(p - d * r), 1e-5 * r);
      ++checked;
    }
  }
  EXPECT_EQ(checked, gradient.synthesized_cells);
  EXPECT_EQ(gradient.synthesized_cells + gradient.no_return_cells, gradient.hole_cells);
}

TEST(FillScan, ThePlanesAroundTheHoleTakeTheDriftOutOfTheReconstruction) {
  const FillCase c = MakeFillCase(kWallScene, 2);
  FillOptions options;
  const FillResult with_planes = FillScan(c.scan, c.hole, options);
  options.planes.enabled = false;
  const FillResult without = FillScan(c.scan, c.hole, options);
  EXPECT_GT(with_planes.plane_cells, with_planes.synthesized_cells / 2);
  EXPECT_EQ(without.plane_cells, 0);
  const FillMetrics on = MeasureFill(with_planes.scan, c.truth, c.hole);
  const FillMetrics off = MeasureFill(without.scan, c.truth, c.hole);
  EXPECT_LT(on.range_rmse_mm, off.range_rmse_mm)
      << "planes " << on.range_rmse_mm << " none " << off.range_rmse_mm;
  EXPECT_LE(on.floating_share, off.floating_share);
  EXPECT_GT(on.within_share, off.within_share);
}

// Offset completion (opt-in): shifted copies of the scan fill the hole behind the box, the greedy fill only what
// no offset reaches; the result is as good as the default's and leaves every cell outside the hole alone.
TEST(FillScan, OffsetCompletionFillsBehindTheBox) {
  const FillCase c = MakeFillCase(kWallScene, 2);
  FillOptions options;
  options.offset_completion = true;
  const FillResult offsets = FillScan(c.scan, c.hole, options);
  options.method = FillMethod::kLaplace;
  const FillResult laplace = FillScan(c.scan, c.hole, options);
  EXPECT_GT(offsets.offset_cells, offsets.hole_cells / 2);
  EXPECT_EQ(offsets.synthesized_cells + offsets.no_return_cells, offsets.hole_cells);
  const FillMetrics o = MeasureFill(offsets.scan, c.truth, c.hole);
  const FillMetrics l = MeasureFill(laplace.scan, c.truth, c.hole);
  EXPECT_LT(o.range_rmse_mm, l.range_rmse_mm / 4)
      << "offsets " << o.range_rmse_mm << " laplace " << l.range_rmse_mm;
  EXPECT_LT(o.floating_share, 0.02);
  const cv::Mat outside = c.hole == 0;
  EXPECT_EQ(cv::countNonZero((offsets.scan.range != c.scan.range) & outside), 0);
  EXPECT_EQ(cv::countNonZero((offsets.scan.valid != c.scan.valid) & outside), 0);
  // Deterministic: the same fill again.
  options.method = FillMethod::kGradient;
  const FillResult again = FillScan(c.scan, c.hole, options);
  EXPECT_EQ(cv::countNonZero(again.scan.range != offsets.scan.range), 0);
  // Its own options reach it: one label copies fewer cells, a weight list of the wrong length is refused.
  options.offsets.labels = 1;
  EXPECT_LT(FillScan(c.scan, c.hole, options).offset_cells, offsets.offset_cells);
  options.offsets = {};
  options.offsets.channel_weights = {1.0f};
  EXPECT_THROW(FillScan(c.scan, c.hole, options), OptionsError);
}

// PatchMatch gives way to the exact search where that is affordable (FillOptions::exact_search_max_cost): the
// same fill as asking for it, and PatchMatch's own with a budget of 0.
TEST(FillScan, SmallHolesGetTheExactSearch) {
  const FillCase c = MakeFillCase(kWallScene, 2);
  FillOptions options;
  const FillResult automatic = FillScan(c.scan, c.hole, options);
  EXPECT_TRUE(automatic.exact_search);
  options.inpaint.search = InpaintSearchKind::kExhaustive;
  const FillResult exact = FillScan(c.scan, c.hole, options);
  EXPECT_TRUE(exact.exact_search);
  EXPECT_EQ(cv::countNonZero(automatic.scan.range != exact.scan.range), 0);
  options.inpaint.search = InpaintSearchKind::kPatchMatch;
  options.exact_search_max_cost = 0;
  const FillResult patchmatch = FillScan(c.scan, c.hole, options);
  EXPECT_FALSE(patchmatch.exact_search);
  // PatchMatch compares fewer sources per patch than the exact search, which scans every one its bound admits.
  EXPECT_LT(patchmatch.candidates_evaluated / std::max(1, patchmatch.patches),
            automatic.candidates_evaluated / std::max(1, automatic.patches));
}

TEST(FillScan, CellsWithNothingBehindStayWithoutAReturn) {
  const FillCase c = MakeFillCase(kSkyScene, 1);
  int sky = 0;
  for (int y = 0; y < c.scan.rows; ++y)
    for (int x = 0; x < c.scan.cols; ++x) sky += c.hole.at<uint8_t>(y, x) && !c.truth.valid.at<uint8_t>(y, x);
  ASSERT_GT(sky, 50);  // the post's top is against the sky
  for (FillMethod method : {FillMethod::kGradient, FillMethod::kLaplace}) {
    FillOptions options;
    options.method = method;
    const FillResult result = FillScan(c.scan, c.hole, options);
    const FillMetrics m = MeasureFill(result.scan, c.truth, c.hole);
    EXPECT_GT(m.return_accuracy, 0.95) << ToString(method);
    EXPECT_GT(result.no_return_cells, sky / 2) << ToString(method);
    if (method == FillMethod::kGradient) EXPECT_LT(m.floating_share, 0.01);
  }
}

// The ground ends 20 m out and the scan's top rows look past its end: a box tall enough to reach the top row
// leaves a hole whose upper rows have no return on either side of it in their row, and must stay without one
// (a patch copied from lower down would bring ground).
TEST(FillScan, RowsWithoutAReturnOnBothSidesOfTheHoleStayWithoutOne) {
  const FillCase c = MakeFillCase(R"({
    "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-35, 35], "elevation_deg": [-25, -2], "columns": 200,
                "rows": 100, "max_range": 60, "seed": 7},
    "objects": [
      {"primitive": "plane", "size": [40, 20], "translate": [0, 10, 0], "label": 0, "texture": "gravel",
       "color": [120, 118, 112]},
      {"primitive": "box", "size": [3.0, 0.8, 2.0], "translate": [0.3, 5, 1.0], "label": 1, "color": [40, 60, 200]}
    ]
  })",
                                  2);
  // Hole cells whose nearest known cells left and right in the row both lack a return.
  cv::Mat between = cv::Mat::zeros(c.hole.size(), CV_8U);
  for (int y = 0; y < c.hole.rows; ++y)
    for (int x = 0; x < c.hole.cols; ++x) {
      if (!c.hole.at<uint8_t>(y, x)) continue;
      int left = x, right = x;
      while (left >= 0 && c.hole.at<uint8_t>(y, left)) --left;
      while (right < c.hole.cols && c.hole.at<uint8_t>(y, right)) ++right;
      between.at<uint8_t>(y, x) = left >= 0 && right < c.hole.cols && !c.scan.valid.at<uint8_t>(y, left) &&
                                  !c.scan.valid.at<uint8_t>(y, right);
    }
  ASSERT_GT(cv::countNonZero(between), 40);
  ASSERT_GT(cv::countNonZero(c.hole.row(0)), 0);  // the hole reaches the scan's top row
  for (FillMethod method : {FillMethod::kGradient, FillMethod::kDepthPatch}) {
    FillOptions options;
    options.method = method;
    const FillResult result = FillScan(c.scan, c.hole, options);
    EXPECT_EQ(cv::countNonZero(result.scan.valid & between), 0) << ToString(method);
    EXPECT_GT(MeasureFill(result.scan, c.truth, c.hole).return_accuracy, 0.975) << ToString(method);
  }
}

TEST(FillScan, EveryMethodRunsOnAScanWithoutIntensityOrColourAndInventsNone) {
  // A PCD or E57 without intensity (and here without colour): the fill has only the range to go by.
  FillCase c = MakeFillCase(kWallScene, 1);
  c.scan.intensity = cv::Mat();
  c.scan.color = cv::Mat();
  for (FillMethod method :
       {FillMethod::kGradient, FillMethod::kLaplace, FillMethod::kDepthPatch, FillMethod::kTelea}) {
    FillOptions options;
    options.method = method;
    const FillResult result = FillScan(c.scan, c.hole, options);
    EXPECT_FALSE(result.scan.has_intensity()) << ToString(method);
    EXPECT_FALSE(result.scan.has_color()) << ToString(method);
    const FillMetrics m = MeasureFill(result.scan, c.truth, c.hole);
    EXPECT_GT(m.return_accuracy, 0.9) << ToString(method);
  }
}

TEST(FillScan, DepthPatchesFloatWhereGradientsDoNot) {
  const FillCase c = MakeFillCase(kWallScene, 2);
  FillOptions options;
  options.method = FillMethod::kDepthPatch;
  const FillMetrics d = MeasureFill(FillScan(c.scan, c.hole, options).scan, c.truth, c.hole);
  options.method = FillMethod::kGradient;
  const FillMetrics g = MeasureFill(FillScan(c.scan, c.hole, options).scan, c.truth, c.hole);
  EXPECT_GT(d.range_rmse_mm, g.range_rmse_mm);
}

TEST(FillScan, SameSeedSameFillOnAnyThreadCount) {
  const FillCase c = MakeFillCase(kWallScene, 1);
  FillOptions options;
  options.inpaint.seed = 3;
  const FillResult a = FillScan(c.scan, c.hole, options);
  FillResult b;
  {
    const ThreadLimit one_thread(1);
    b = FillScan(c.scan, c.hole, options);
  }
  EXPECT_EQ(cv::norm(a.scan.range, b.scan.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.scan.color, b.scan.color, cv::NORM_INF), 0.0);
  // Another seed draws other patches: the seed is used (by PatchMatch's draws; the exact search and the band
  // planes, refitted by least squares after RANSAC, give the same answer for every seed).
  options.exact_search_max_cost = 0;
  const FillResult drawn = FillScan(c.scan, c.hole, options);
  options.inpaint.seed = 4;
  const FillResult other = FillScan(c.scan, c.hole, options);
  EXPECT_GT(cv::norm(drawn.scan.range, other.scan.range, cv::NORM_INF), 0.0);
}

TEST(FillScan, BadAndEdgeCaseMasks) {
  FillCase c = MakeFillCase(kWallScene, 1);
  EXPECT_THROW(FillScan(c.scan, cv::Mat(c.scan.rows + 1, c.scan.cols, CV_8U, cv::Scalar(0))), InputError);
  EXPECT_THROW(FillScan(c.scan, cv::Mat(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(255))), InputError);
  EXPECT_THROW(FillScan(c.scan, cv::Mat(c.scan.rows, c.scan.cols, CV_32F, cv::Scalar(1))), InputError);
  // An empty mask: an exact copy, nothing synthesized.
  const FillResult empty = FillScan(c.scan, cv::Mat(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(0)));
  EXPECT_EQ(empty.synthesized_cells, 0);
  EXPECT_EQ(cv::norm(empty.scan.range, c.scan.range, cv::NORM_INF), 0.0);
  // ... which says so (#35: `fill` with an empty mask exited 0 silently), where a real hole says nothing.
  ASSERT_EQ(empty.warnings.size(), 1u);
  EXPECT_NE(empty.warnings[0].find("mask is empty"), std::string::npos) << empty.warnings[0];
  EXPECT_TRUE(FillScan(c.scan, c.hole).warnings.empty());
  EXPECT_EQ(ToJson(empty)["warnings"], nlohmann::ordered_json(empty.warnings));
  // A hole touching the image border, in a scan without colour (intensity guides).
  Scan grey = c.scan;
  grey.color.release();
  cv::Mat border(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(0));
  border(cv::Rect(0, c.scan.rows - 20, 30, 20)) = 255;
  for (FillMethod method :
       {FillMethod::kGradient, FillMethod::kLaplace, FillMethod::kDepthPatch, FillMethod::kTelea}) {
    for (bool offsets : {false, true}) {
      if (offsets && method != FillMethod::kGradient && method != FillMethod::kDepthPatch) continue;
      FillOptions options;
      options.method = method;
      options.offset_completion = offsets;
      const FillResult result = FillScan(grey, border, options);
      const FillMetrics m = MeasureFill(result.scan, c.truth, border);
      const std::string what = ToString(method) + (offsets ? " with offsets" : "");
      EXPECT_GT(result.synthesized_cells, 500) << what;
      double low = 0, high = 0;
      cv::minMaxLoc(result.scan.range, &low, &high, nullptr, nullptr, border & (result.scan.valid != 0));
      EXPECT_GT(low, 0.5) << what;  // finite, in front of the scanner
      EXPECT_LT(high, 40.0) << what;
      // The membrane and fast marching flatten the ground against the image border (no flux there); the
      // gradient fill continues its slope.
      if (method == FillMethod::kGradient) EXPECT_LT(m.range_rmse_mm, 100.0) << what;
    }
  }
  // Offset completion on a tiny scan (fewer known patches than the statistics want) and on a hole that leaves a
  // band of 12 known columns: a fill; a hole that leaves one column: the same clear error as without offsets.
  {
    FillOptions options;
    options.offset_completion = true;
    cv::Mat most(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(255));
    most.colRange(c.scan.cols / 2, c.scan.cols / 2 + 12).setTo(0);
    const FillResult result = FillScan(c.scan, most, options);
    EXPECT_EQ(result.synthesized_cells + result.no_return_cells, result.hole_cells);
    EXPECT_GT(result.synthesized_cells, 0);
    cv::Mat one_column(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(255));
    one_column.col(c.scan.cols / 2).setTo(0);
    EXPECT_THROW(FillScan(c.scan, one_column, options), InputError);
    EXPECT_THROW(FillScan(c.scan, one_column, FillOptions{}), InputError);
    const cv::Rect corner(0, 0, 20, 16);
    Scan tiny = c.scan;
    for (cv::Mat* m : {&tiny.range, &tiny.point, &tiny.direction, &tiny.valid, &tiny.color, &tiny.intensity,
                       &tiny.label, &tiny.normal, &tiny.curvature, &tiny.true_range, &tiny.synthesized})
      if (!m->empty()) *m = (*m)(corner).clone();
    tiny.rows = corner.height;
    tiny.cols = corner.width;
    cv::Mat small_hole = cv::Mat::zeros(corner.size(), CV_8U);
    small_hole(cv::Rect(8, 6, 3, 3)).setTo(255);
    const FillResult small = FillScan(tiny, small_hole, options);
    EXPECT_EQ(small.hole_cells, 9);
    EXPECT_EQ(small.synthesized_cells + small.no_return_cells, 9);
  }
  FillOptions bad;
  bad.inpaint.patch_radius = 0;
  EXPECT_THROW(FillScan(c.scan, border, bad), OptionsError);
  EXPECT_THROW(ParseEnum<FillMethod>("magic"), OptionsError);
}

}  // namespace
}  // namespace lidarshop
