#include "lidarshop/segment/segment.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/render/strokes.h"
#include "lidarshop/segment/segment_test_util.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using segment_test::MakeBoxOnGround;
using segment_test::TruthMask;

// One short object stroke in the middle of the box, one background stroke on the ground to the left.
cv::Mat MakeStrokes(const Scan& scan) {
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  cv::Mat truth = TruthMask(scan);
  cv::Rect box = cv::boundingRect(truth);
  const cv::Point c(box.x + box.width / 2, box.y + box.height / 2);
  cv::line(strokes, c - cv::Point(box.width / 6, 0), c + cv::Point(box.width / 6, 0),
           cv::Scalar(kStrokeObject), 2);
  cv::line(strokes, cv::Point(scan.cols / 10, scan.rows - 10), cv::Point(scan.cols / 4, scan.rows - 10),
           cv::Scalar(kStrokeBackground), 2);
  return strokes;
}

TEST(SegmentTest, TwoStepCutsTheBoxAndStepOneIsInsideIt) {
  const Scan scan = MakeBoxOnGround(160, 200, cv::Vec3b(118, 138, 112), 3);
  const cv::Mat strokes = MakeStrokes(scan);
  const SegmentResult result = SegmentObject(scan, strokes, SegmentOptions());
  const MaskScores step1 = ScoreMask(result.step1_mask, TruthMask(scan), scan.valid);
  const MaskScores final_scores = ScoreMask(result.mask, TruthMask(scan), scan.valid);
  EXPECT_GE(step1.precision, 0.99);
  EXPECT_GT(final_scores.iou, 0.9) << "precision " << final_scores.precision << " recall "
                                   << final_scores.recall;
  EXPECT_GE(final_scores.recall, step1.recall);
  // Some ring cells must have been inferred as background (the wall around the box), none on the box.
  EXPECT_GT(cv::countNonZero(result.inferred_background), 0);
  EXPECT_EQ(cv::countNonZero(result.inferred_background & TruthMask(scan)), 0);
}

TEST(SegmentTest, CellsWithoutReturnAreNeverObjectAndSplitTheGraph) {
  Scan scan = MakeBoxOnGround(120, 160, cv::Vec3b(118, 138, 112), 4);
  // Punch a hole of no returns through the middle of the box.
  cv::Rect box = cv::boundingRect(TruthMask(scan));
  cv::Rect hole(box.x + box.width / 2 - 2, box.y, 4, box.height / 3);
  scan.valid(hole).setTo(0);
  scan.range(hole).setTo(0);
  scan.point(hole).setTo(cv::Scalar::all(0));
  scan.label(hole).setTo(kNoLabel);
  for (SegmentMethod method :
       {SegmentMethod::kTwoStep, SegmentMethod::kDepth, SegmentMethod::kColor, SegmentMethod::kRgbd}) {
    SegmentOptions options;
    options.method = method;
    const SegmentResult result = SegmentObject(scan, MakeStrokes(scan), options);
    EXPECT_EQ(cv::countNonZero(result.mask & (scan.valid == 0)), 0) << ToString(method);
    EXPECT_GT(result.object_cells, 0) << ToString(method);
  }
}

TEST(SegmentTest, DeterministicAndGmmWorks) {
  const Scan scan = MakeBoxOnGround(100, 140, cv::Vec3b(118, 138, 112), 5);
  SegmentOptions options;
  options.model = AppearanceModel::kGmm;
  const SegmentResult a = SegmentObject(scan, MakeStrokes(scan), options);
  const SegmentResult b = SegmentObject(scan, MakeStrokes(scan), options);
  EXPECT_EQ(cv::countNonZero(a.mask != b.mask), 0);
  EXPECT_GT(ScoreMask(a.mask, TruthMask(scan), scan.valid).iou, 0.85);
}

TEST(SegmentTest, RefineAddsHardConstraintsIncrementally) {
  const Scan scan = MakeBoxOnGround(120, 160, cv::Vec3b(118, 138, 112), 6);
  SegmentOptions options;
  options.method = SegmentMethod::kColor;
  SegmentSession session(scan, options);
  const SegmentResult first = session.Run(MakeStrokes(scan));
  // Mark a band across the box's lower half as background: those cells must leave the object.
  cv::Rect box = cv::boundingRect(TruthMask(scan));
  cv::Mat extra(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int band_row = box.y + (3 * box.height) / 4;
  cv::line(extra, cv::Point(box.x - 3, band_row), cv::Point(box.x + box.width + 3, band_row),
           cv::Scalar(kStrokeBackground), 1);
  const SegmentResult refined = session.Refine(extra);
  EXPECT_EQ(cv::countNonZero(refined.mask & (extra == kStrokeBackground)), 0);
  EXPECT_LT(refined.object_cells, first.object_cells);
  // Background strokes only remove cells (refine_monotone).
  EXPECT_EQ(cv::countNonZero(refined.mask & ~first.mask), 0);
  // The band cuts the box: what is below it is no longer connected to the object stroke.
  EXPECT_EQ(cv::countNonZero(refined.mask(cv::Rect(box.x, band_row + 2, box.width, 1))), 0);
  // Refine before Run is a programming error.
  SegmentSession fresh(scan, options);
  EXPECT_THROW(fresh.Refine(extra), std::logic_error);
}

TEST(SegmentTest, StepThreeRegionOfInterestMatchesTheWholeImageCut) {
  const Scan scan = MakeBoxOnGround(160, 200, cv::Vec3b(118, 138, 112), 3);
  const cv::Mat strokes = MakeStrokes(scan);
  SegmentOptions whole;
  whole.roi_margin_cells = 0;
  SegmentOptions roi;
  roi.roi_margin_cells = 10;
  roi.roi_margin_fraction = 0.2;
  const SegmentResult a = SegmentObject(scan, strokes, whole);
  const SegmentResult b = SegmentObject(scan, strokes, roi);
  EXPECT_EQ(a.graph_nodes, scan.CountValid());
  EXPECT_GT(b.graph_nodes, 0);
  EXPECT_LT(b.graph_nodes, scan.CountValid() / 2);
  EXPECT_EQ(cv::countNonZero(a.step1_mask != b.step1_mask), 0);
  // Same object up to a few boundary cells.
  EXPECT_GT(ScoreMask(b.mask, a.mask, scan.valid).iou, 0.98);
  EXPECT_GT(ScoreMask(b.mask, TruthMask(scan), scan.valid).iou, 0.9);
  // Deterministic.
  const SegmentResult c = SegmentObject(scan, strokes, roi);
  EXPECT_EQ(cv::countNonZero(b.mask != c.mask), 0);
  // Nothing outside the region of interest.
  const cv::Rect box = cv::boundingRect(b.step1_mask);
  const int margin = std::max(10, static_cast<int>(std::ceil(0.2 * std::max(box.width, box.height))));
  cv::Mat outside(scan.rows, scan.cols, CV_8U, cv::Scalar(255));
  outside(cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
          cv::Rect(0, 0, scan.cols, scan.rows))
      .setTo(0);
  EXPECT_EQ(cv::countNonZero(b.mask & outside), 0);
}

TEST(SegmentTest, RefineOutsideTheRegionOfInterestReRunsOnTheWholeImage) {
  const Scan scan = MakeBoxOnGround(160, 200, cv::Vec3b(118, 138, 112), 3);
  SegmentOptions options;
  options.roi_margin_cells = 5;
  options.roi_margin_fraction = 0;
  SegmentSession session(scan, options);
  const SegmentResult first = session.Run(MakeStrokes(scan));
  ASSERT_LT(first.graph_nodes, scan.CountValid());
  // An object stroke inside the ROI: incremental, the graph stays the ROI's.
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  cv::Mat inside(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  cv::line(inside, cv::Point(box.x + 3, box.y + box.height - 4), cv::Point(box.x + 8, box.y + box.height - 4),
           cv::Scalar(kStrokeObject), 1);
  const SegmentResult refined = session.Refine(inside);
  EXPECT_EQ(refined.graph_nodes, first.graph_nodes);
  EXPECT_EQ(cv::countNonZero((inside == kStrokeObject) & (refined.mask == 0) & (scan.valid != 0)), 0);
  // Object strokes only add cells (refine_monotone), on the incremental path and on the whole-image re-run.
  EXPECT_EQ(cv::countNonZero(first.mask & ~refined.mask), 0);
  // An object stroke on the wall far from the box (a second object): outside the ROI, so the cut is re-run on
  // the whole image and the stroke cells become object.
  cv::Mat far(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Mat wall = (scan.valid != 0) & (TruthMask(scan) == 0);
  int far_row = -1;
  for (int row = 0; row < scan.rows && far_row < 0; ++row) {
    if (wall.at<uint8_t>(row, 5) != 0 && wall.at<uint8_t>(row, 15) != 0) far_row = row;
  }
  ASSERT_GE(far_row, 0);
  cv::line(far, cv::Point(5, far_row), cv::Point(15, far_row), cv::Scalar(kStrokeObject), 1);
  const SegmentResult again = session.Refine(far);
  EXPECT_EQ(again.graph_nodes, scan.CountValid());
  EXPECT_EQ(cv::countNonZero((far == kStrokeObject) & (again.mask == 0)), 0);
  EXPECT_EQ(cv::countNonZero(refined.mask & ~again.mask), 0);
  EXPECT_GT(ScoreMask(again.mask & TruthMask(scan), TruthMask(scan), scan.valid).iou, 0.9);
}

TEST(SegmentTest, EnclosedNoReturnCellsOnlyInsideTheOutline) {
  cv::Mat mask = cv::Mat::zeros(12, 12, CV_8U), valid(12, 12, CV_8U, cv::Scalar(1));
  mask(cv::Rect(2, 2, 6, 6)).setTo(255);
  valid(cv::Rect(4, 4, 2, 2)).setTo(0);   // a window inside the object
  valid(cv::Rect(7, 7, 3, 1)).setTo(0);   // on the object's edge, reaching the background
  valid(cv::Rect(0, 10, 3, 2)).setTo(0);  // at the image border
  mask.setTo(0, valid == 0);
  const cv::Mat enclosed = EnclosedNoReturnCells(mask, valid);
  EXPECT_EQ(cv::countNonZero(enclosed), 4);
  EXPECT_EQ(cv::countNonZero(enclosed(cv::Rect(4, 4, 2, 2))), 4);
}

// The flood within the mask's box equals the flood of the whole image (the earlier implementation, written
// here as the reference) on random masks and returns, objects touching the border included; and the in-place
// form with a box adds exactly those cells.
TEST(SegmentTest, EnclosedNoReturnCellsInTheBoxEqualTheWholeImagesFlood) {
  const auto reference = [](const cv::Mat& mask, const cv::Mat& valid) {
    cv::Mat outside = (mask == 0) / 255, padded;
    cv::copyMakeBorder(outside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(1));
    cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(2), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
    return cv::Mat((padded(cv::Rect(1, 1, mask.cols, mask.rows)) == 1) & (valid == 0));
  };
  cv::RNG rng(20261128);
  int with_enclosed = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int rows = 20 + trial % 17, cols = 25 + trial % 13;
    cv::Mat valid(rows, cols, CV_8U), mask = cv::Mat::zeros(rows, cols, CV_8U);
    rng.fill(valid, cv::RNG::UNIFORM, 0, 4);  // a quarter without a return
    valid = valid != 0;
    const cv::Point center(rng.uniform(0, cols), rng.uniform(0, rows));
    cv::ellipse(mask, center, cv::Size(rng.uniform(2, cols / 2), rng.uniform(2, rows / 2)), 0, 0, 360,
                cv::Scalar(255), cv::FILLED);
    mask.setTo(0, valid == 0);
    const cv::Mat expected = reference(mask, valid);
    with_enclosed += cv::countNonZero(expected) > 0;
    EXPECT_EQ(cv::countNonZero(EnclosedNoReturnCells(mask, valid) != expected), 0) << "trial " << trial;
    cv::Mat in_place = mask.clone();
    AddEnclosedNoReturnCells(valid, cv::boundingRect(mask), &in_place);
    EXPECT_EQ(cv::countNonZero(in_place != (mask | expected)), 0) << "trial " << trial;
  }
  EXPECT_GT(with_enclosed, 20);  // the trials do enclose cells
}

TEST(SegmentTest, NoReturnCellsInsideTheObjectJoinTheMask) {
  Scan scan = MakeBoxOnGround(120, 160, cv::Vec3b(40, 60, 200), 9);
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  // Black tyres: a patch of the box without returns, away from the box's outline and from the strokes.
  const cv::Rect hole(box.x + box.width / 2 + 2, box.y + box.height / 4, 3, 3);
  scan = MaskScan(scan, [&] {
    cv::Mat keep(scan.rows, scan.cols, CV_8U, cv::Scalar(255));
    keep(hole).setTo(0);
    return keep;
  }());
  const cv::Mat strokes = MakeStrokes(scan);
  ASSERT_EQ(cv::countNonZero(strokes(hole)), 0);
  SegmentOptions options;
  const SegmentResult with = SegmentObject(scan, strokes, options);
  options.include_enclosed_no_return = false;
  const SegmentResult without = SegmentObject(scan, strokes, options);
  EXPECT_EQ(cv::countNonZero(without.mask(hole)), 0);
  EXPECT_EQ(cv::countNonZero(with.mask(hole)), hole.area());
  EXPECT_EQ(cv::countNonZero(with.mask & (scan.valid != 0)), without.object_cells);
  EXPECT_EQ(with.object_cells, without.object_cells + hole.area());
}

TEST(SegmentTest, WholeObjectGrowthJoinsAPartOfAnotherColourButNotTheGround) {
  // A blue box whose lower half is painted the grass's colour: one object in depth, two in colour.
  Scan scan = Clone(MakeBoxOnGround(140, 180, cv::Vec3b(40, 60, 200), 11));
  const cv::Mat truth = TruthMask(scan);
  const cv::Rect box = cv::boundingRect(truth);
  const cv::Rect lower(box.x, box.y + box.height / 2, box.width, box.height - box.height / 2);
  scan.color(lower).setTo(cv::Scalar(74, 112, 42), truth(lower));
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int stroke_row = box.y + box.height / 4;
  cv::line(strokes, cv::Point(box.x + box.width / 3, stroke_row),
           cv::Point(box.x + 2 * box.width / 3, stroke_row), cv::Scalar(kStrokeObject), 1);
  cv::line(strokes, cv::Point(2, scan.rows - 3), cv::Point(20, scan.rows - 3), cv::Scalar(kStrokeBackground),
           1);
  SegmentOptions options;
  options.grow_whole_object = false;
  const MaskScores without = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  options.grow_whole_object = true;
  const MaskScores with = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  EXPECT_LT(without.iou, 0.8);      // the colour cut keeps to the blue half
  EXPECT_GT(with.iou, 0.95);        // growth joins the green half...
  EXPECT_GT(with.precision, 0.98);  // ...and stops at the ground it stands on
}

TEST(SegmentTest, BadStrokesAndOptionsAreRejected) {
  const Scan scan = MakeBoxOnGround(60, 80, cv::Vec3b(118, 138, 112), 7);
  cv::Mat only_object(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  only_object.at<uint8_t>(30, 40) = kStrokeObject;
  EXPECT_THROW(SegmentObject(scan, only_object), InputError);
  EXPECT_THROW(SegmentObject(scan, cv::Mat(10, 10, CV_8U, cv::Scalar(0))), InputError);
  SegmentOptions options;
  options.sigma_scale = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = SegmentOptions();
  options.depth_step.smoothness = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  EXPECT_THROW(ParseEnum<SegmentMethod>("magic"), OptionsError);
  EXPECT_EQ(ParseEnum<SegmentMethod>("two-step"), SegmentMethod::kTwoStep);
}

TEST(SegmentTest, ScoreMaskCounts) {
  cv::Mat truth(4, 4, CV_8U, cv::Scalar(0)), mask(4, 4, CV_8U, cv::Scalar(0));
  truth(cv::Rect(0, 0, 2, 2)).setTo(255);  // 4 cells
  mask(cv::Rect(1, 0, 2, 2)).setTo(255);   // 2 overlap, 2 false positives
  const MaskScores s = ScoreMask(mask, truth);
  EXPECT_EQ(s.true_positive, 2);
  EXPECT_EQ(s.false_positive, 2);
  EXPECT_EQ(s.false_negative, 2);
  EXPECT_DOUBLE_EQ(s.iou, 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(s.precision, 0.5);
}

TEST(SegmentTest, AScanWithoutColourOrIntensityIsCutByDepth) {
  // A PCD or E57 that holds only points: the colour terms are constant, the depth still separates the box.
  Scan scan = MakeBoxOnGround(160, 200, cv::Vec3b(118, 138, 112), 3);
  scan.color = cv::Mat();
  scan.intensity = cv::Mat();
  const cv::Mat strokes = MakeStrokes(scan);
  const SegmentResult result = SegmentObject(scan, strokes, SegmentOptions());
  const MaskScores step1 = ScoreMask(result.step1_mask, TruthMask(scan), scan.valid);
  const MaskScores final_scores = ScoreMask(result.mask, TruthMask(scan), scan.valid);
  EXPECT_GE(step1.precision, 0.99);
  // Step 3 has nothing to go by: the depth cut is the answer (not a flood of the ring).
  EXPECT_EQ(cv::norm(result.mask, result.step1_mask, cv::NORM_INF), 0.0);
  EXPECT_GE(final_scores.precision, 0.99);
  EXPECT_GT(final_scores.iou, 0.5) << "recall " << final_scores.recall;
  SegmentOptions color;
  color.method = SegmentMethod::kColor;
  EXPECT_THROW(SegmentObject(scan, strokes, color), InputError);
  // The baseline and the overlay run too (plain grey under the tint).
  EXPECT_EQ(GrabCutFromStrokes(scan, strokes, 2).type(), CV_8U);
  const cv::Mat overlay = SegmentOverlay(scan, result.mask, strokes);
  EXPECT_EQ(overlay.size(), cv::Size(scan.cols, scan.rows));
}

TEST(SegmentTest, GrabCutBaselineAndOverlayRun) {
  const Scan scan = MakeBoxOnGround(80, 100, cv::Vec3b(40, 60, 200), 8);
  const cv::Mat strokes = MakeStrokes(scan);
  const cv::Mat gc = GrabCutFromStrokes(scan, strokes, 3);
  ASSERT_EQ(gc.type(), CV_8U);
  // A blue box on green grass is easy for colour alone.
  EXPECT_GT(ScoreMask(gc, TruthMask(scan), scan.valid).iou, 0.6);
  const cv::Mat overlay = SegmentOverlay(scan, gc, strokes);
  EXPECT_EQ(overlay.type(), CV_8UC3);
  const cv::Point stroke_cell = [&] {
    std::vector<cv::Point> cells;
    cv::findNonZero(strokes == kStrokeObject, cells);
    return cells.front();
  }();
  EXPECT_EQ(overlay.at<cv::Vec3b>(stroke_cell), cv::Vec3b(0, 255, 0));
}

TEST(SegmentStrokesTest, PaintedImageAndJson) {
  cv::Mat painted(4, 5, CV_8UC3, cv::Scalar(0, 0, 0));
  painted.at<cv::Vec3b>(1, 1) = cv::Vec3b(0, 255, 0);
  painted.at<cv::Vec3b>(2, 3) = cv::Vec3b(250, 10, 20);
  painted.at<cv::Vec3b>(3, 4) = cv::Vec3b(74, 112, 42);  // grass-like green: not saturated, not a stroke
  const cv::Mat s = StrokesFromImage(painted);
  EXPECT_EQ(s.at<uint8_t>(1, 1), kStrokeObject);
  EXPECT_EQ(s.at<uint8_t>(2, 3), kStrokeBackground);
  EXPECT_EQ(s.at<uint8_t>(3, 4), kStrokeNone);
  EXPECT_EQ(cv::countNonZero(StrokesFromImage(StrokesToImage(s)) != s), 0);

  const cv::Mat j = StrokesFromJson(
      R"({"strokes": [{"label": "object", "points": [[1, 1], [3, 1]]}, {"label": "background", "points": [[0, 3]]}]})",
      4, 5);
  EXPECT_EQ(j.at<uint8_t>(1, 2), kStrokeObject);  // row 1, col 2: on the polyline
  EXPECT_EQ(j.at<uint8_t>(3, 0), kStrokeBackground);
  EXPECT_EQ(cv::countNonZero(j), 4);

  EXPECT_THROW(StrokesFromJson("{", 4, 5), InputError);
  EXPECT_THROW(StrokesFromJson(R"({"strokes": [{"label": "tree", "points": [[0, 0]]}]})", 4, 5), InputError);
  EXPECT_THROW(StrokesFromJson(R"({"strokes": [{"label": "object", "points": [[9, 0]]}]})", 4, 5),
               InputError);
  try {
    StrokesFromJson(R"({"strokes": [{"label": "object", "points": [[0, 0], ["a", 1]]}]})", 4, 5, "s.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stroke 0"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("points[1]"), std::string::npos);
  }
}

}  // namespace
}  // namespace lidarshop
