// Coarse to fine (SegmentOptions::coarse_max_cells): a large scan is cut on a coarser level and its outline
// re-cut at full resolution; the result matches the full-resolution cut, is sharper than the level's cut
// taken to full resolution, and refinements keep the rules of Refine().
#include "lidarshop/segment/coarse_to_fine.h"

#include <optional>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/render/strokes.h"
#include "lidarshop/scan/scan_level.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_test_util.h"

namespace lidarshop {
namespace {

using segment_internal::CoarseFactor;
using segment_internal::CoarseStrokes;
using segment_internal::FullResolution;
using segment_internal::FullResolutionWithReturns;
using segment_test::MakeBoxOnGround;
using segment_test::TruthMask;

// 480 x 800 cells, the box about 170 columns wide.
Scan MakeScene() { return MakeBoxOnGround(480, 800, cv::Vec3b(118, 138, 112), 5); }

cv::Mat Strokes(const Scan& scan) {
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  const cv::Point c(box.x + box.width / 2, box.y + box.height / 2);
  cv::line(strokes, c - cv::Point(box.width / 4, 0), c + cv::Point(box.width / 4, 0),
           cv::Scalar(kStrokeObject), 3);
  cv::line(strokes, cv::Point(box.x - 20, box.y + box.height + 12),
           cv::Point(box.x + box.width + 20, box.y + box.height + 12), cv::Scalar(kStrokeBackground), 3);
  return strokes;
}

SegmentOptions CoarseAbove(int max_cells) {
  SegmentOptions options;
  options.coarse_max_cells = max_cells;
  return options;
}

TEST(CoarseToFineTest, TheFactorIsThePowerOfTwoThatFits) {
  EXPECT_EQ(CoarseFactor(480, 800, 0), 1);
  EXPECT_EQ(CoarseFactor(480, 800, 384000), 1);
  EXPECT_EQ(CoarseFactor(480, 800, 383999), 2);
  EXPECT_EQ(CoarseFactor(480, 800, 30000), 4);  // 120 x 200 = 24000
  EXPECT_EQ(CoarseFactor(2250, 3600, 1000000), 4);
}

TEST(CoarseToFineTest, StrokesAndMasksBetweenTheLevels) {
  // A 5 x 5 scan at 10 m, but for cell (2, 0) at 5 m (something before the wall) and no return at (4, 4).
  Scan scan = MakeScan(5, 5);
  scan.valid.setTo(kValid);
  scan.range.setTo(10.0f);
  scan.range.at<float>(2, 0) = 5.0f;
  scan.valid.at<uint8_t>(4, 4) = 0;
  scan.range.at<float>(4, 4) = 0.0f;
  const cv::Mat cells = DecimatedCells(scan, 2);
  cv::Mat strokes(5, 5, CV_8U, cv::Scalar(kStrokeNone));
  strokes.at<uint8_t>(0, 0) = kStrokeObject;
  strokes.at<uint8_t>(0, 2) = kStrokeObject;
  strokes.at<uint8_t>(1, 3) = kStrokeBackground;  // the same block as (0, 2): background wins
  strokes.at<uint8_t>(3, 1) = kStrokeObject;      // block (1, 0), whose cell (2, 0) is 5 m before the stroke
  strokes.at<uint8_t>(4, 4) = kStrokeBackground;  // no return: says nothing
  const cv::Mat coarse = CoarseStrokes(scan, cells, strokes, 2);
  ASSERT_EQ(coarse.size(), cv::Size(3, 3));
  EXPECT_EQ(coarse.at<uint8_t>(0, 0), kStrokeObject);
  EXPECT_EQ(coarse.at<uint8_t>(0, 1), kStrokeBackground);
  EXPECT_EQ(coarse.at<uint8_t>(1, 0), kStrokeNone);
  EXPECT_EQ(cv::countNonZero(coarse), 2);
  cv::Mat level(3, 3, CV_8U, cv::Scalar(0));
  level.at<uint8_t>(1, 2) = 255;
  const cv::Mat full = FullResolution(level, 2, cv::Size(5, 5));
  ASSERT_EQ(full.size(), cv::Size(5, 5));
  EXPECT_EQ(cv::countNonZero(full), 2);  // rows 2-3 x column 4: the block is cut by the scan's edge
  EXPECT_EQ(full.at<uint8_t>(2, 4), 255);
  EXPECT_EQ(full.at<uint8_t>(3, 4), 255);
  // Written block by block where the level is set: the same as the whole level brought up and ANDed with the
  // cells that returned, here with a level block cut by the scan's edge and cells without a return in it.
  cv::Mat coarse_mask(3, 3, CV_8U, cv::Scalar(0)), valid(5, 5, CV_8U, cv::Scalar(1));
  coarse_mask.at<uint8_t>(0, 0) = coarse_mask.at<uint8_t>(1, 2) = coarse_mask.at<uint8_t>(2, 2) = 255;
  valid.at<uint8_t>(0, 1) = valid.at<uint8_t>(4, 4) = 0;
  const cv::Mat expected = FullResolution(coarse_mask, 2, cv::Size(5, 5)) & (valid != 0);
  EXPECT_EQ(cv::countNonZero(FullResolutionWithReturns(coarse_mask, 2, valid) != expected), 0);
  EXPECT_EQ(cv::countNonZero(expected), 3 + 2);
}

TEST(CoarseToFineTest, TheOutlineCutMatchesTheFullResolutionCut) {
  const Scan scan = MakeScene();
  const cv::Mat strokes = Strokes(scan), truth = TruthMask(scan);
  const SegmentResult full = SegmentObject(scan, strokes, CoarseAbove(0));
  const SegmentResult fine = SegmentObject(scan, strokes, CoarseAbove(30000));
  EXPECT_EQ(full.coarse_factor, 1);
  ASSERT_EQ(fine.coarse_factor, 4);
  // The level's own cut, taken to full resolution block by block: what the outline cut improves on.
  const SegmentResult level = SegmentObject(
      DecimateScan(scan, 4), CoarseStrokes(scan, DecimatedCells(scan, 4), strokes, 4), CoarseAbove(0));
  const cv::Mat blocky = FullResolution(level.mask, 4, cv::Size(scan.cols, scan.rows)) & (scan.valid != 0);
  const double iou_full = ScoreMask(full.mask, truth, scan.valid).iou;
  const double iou_fine = ScoreMask(fine.mask, truth, scan.valid).iou;
  const double iou_blocky = ScoreMask(blocky, truth, scan.valid).iou;
  EXPECT_GT(iou_full, 0.97);
  EXPECT_GT(iou_fine, iou_full - 0.01);
  EXPECT_GT(iou_fine, iou_blocky);
  EXPECT_GT(ScoreMask(fine.mask, full.mask).iou, 0.98);
  EXPECT_LT(cv::countNonZero(fine.mask != full.mask), cv::countNonZero(blocky != full.mask));
  // The full-resolution graph is the outline's band, not the object.
  EXPECT_LT(fine.graph_nodes, fine.object_cells);
  EXPECT_EQ(fine.object_cells, cv::countNonZero(fine.mask));
  EXPECT_TRUE(fine.warnings.empty());
}

TEST(CoarseToFineTest, RefinementsKeepTheirRules) {
  const Scan scan = MakeScene();
  SegmentSession session(scan, CoarseAbove(30000));
  const SegmentResult first = session.Run(Strokes(scan));
  ASSERT_EQ(first.coarse_factor, 4);
  const cv::Rect box = cv::boundingRect(first.mask);
  // An object stroke inside the object adds, never removes.
  cv::Mat inside(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  cv::line(inside, cv::Point(box.x + box.width / 2, box.y + box.height / 4),
           cv::Point(box.x + box.width / 2, box.y + box.height * 3 / 4), cv::Scalar(kStrokeObject), 3);
  const SegmentResult added = session.Refine(inside);
  EXPECT_EQ(added.coarse_factor, 4);
  EXPECT_EQ(cv::countNonZero(first.mask & ~added.mask), 0);
  // A background stroke across the object's left end removes cells there and nowhere else.
  cv::Mat across(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int col = box.x + box.width / 8;
  cv::line(across, cv::Point(col, box.y - 5), cv::Point(col, box.y + box.height + 5),
           cv::Scalar(kStrokeBackground), 3);
  const SegmentResult removed = session.Refine(across);
  EXPECT_LT(removed.object_cells, added.object_cells);
  EXPECT_EQ(cv::countNonZero(removed.mask & ~added.mask), 0);
  EXPECT_EQ(cv::countNonZero(removed.mask & (across == kStrokeBackground)), 0);
  const cv::Mat lost = added.mask & ~removed.mask;
  EXPECT_LT(cv::boundingRect(lost).x + cv::boundingRect(lost).width, box.x + box.width / 2);
}

// The live update (RefineTo): all the strokes now, the session finds what they add. On a level as on a scan
// cut whole, its result is Refine()'s with the added strokes; strokes erased or relabelled since, or no Run()
// yet, ask for a full cut (nullopt).
TEST(CoarseToFineTest, RefineToIsRefineOfWhatTheStrokesAdd) {
  const Scan scan = MakeScene();
  for (const int64_t coarse_above : {int64_t{30000}, int64_t{0}}) {
    SCOPED_TRACE(coarse_above);
    const cv::Mat strokes = Strokes(scan);
    SegmentSession by_refine(scan, CoarseAbove(coarse_above)), by_refine_to(scan, CoarseAbove(coarse_above));
    EXPECT_FALSE(by_refine_to.RefineTo(strokes).has_value());  // no Run() yet
    const SegmentResult first = by_refine.Run(strokes);
    by_refine_to.Run(strokes);
    EXPECT_EQ(first.coarse_factor, coarse_above > 0 ? 4 : 1);
    EXPECT_EQ(by_refine_to.RefineTo(strokes)->object_cells, first.object_cells);  // nothing added
    const cv::Rect box = cv::boundingRect(first.mask);
    cv::Mat added(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
    const int col = box.x + box.width / 8;
    cv::line(added, cv::Point(col, box.y - 5), cv::Point(col, box.y + box.height + 5),
             cv::Scalar(kStrokeBackground), 3);
    cv::Mat now = strokes.clone();
    added.copyTo(now, added != kStrokeNone);
    const SegmentResult refined = by_refine.Refine(added);
    const cv::Rect painted = cv::boundingRect(now);
    const std::optional<SegmentResult> refined_to = by_refine_to.RefineTo(now, painted);
    ASSERT_TRUE(refined_to.has_value());
    EXPECT_LT(refined.object_cells, first.object_cells);
    EXPECT_EQ(refined_to->object_cells, refined.object_cells);
    EXPECT_EQ(cv::countNonZero(refined_to->mask != refined.mask), 0);
    // The object's box holds the whole object, and the count is the mask's.
    EXPECT_EQ(cv::countNonZero(refined_to->mask(refined_to->object_box)), refined_to->object_cells);
    EXPECT_EQ(cv::countNonZero(refined_to->mask), refined_to->object_cells);
    // An erased stroke cell (one of Run()'s) or a relabelled one: a full cut is needed.
    cv::Mat erased = now.clone();
    std::vector<cv::Point> object_stroke;
    cv::findNonZero(strokes == kStrokeObject, object_stroke);
    ASSERT_FALSE(object_stroke.empty());
    const cv::Point stroked = object_stroke.front();
    erased.at<uint8_t>(stroked) = kStrokeNone;
    EXPECT_EQ(strokes.at<uint8_t>(stroked), kStrokeObject);
    EXPECT_FALSE(by_refine_to.RefineTo(erased).has_value());
    cv::Mat relabelled = now.clone();
    relabelled.setTo(kStrokeObject, added == kStrokeBackground);
    EXPECT_FALSE(by_refine_to.RefineTo(relabelled, painted).has_value());
  }
}

TEST(CoarseToFineTest, AStrokeTheLevelCannotSeeStillHolds) {
  // A pole one ray wide 1 m before the box, on columns the level never takes (every 4th column from the
  // third: the level's rays are the second of each block), stroked as background from top to bottom of the
  // box: the level sees only the box behind it, yet no stroked cell may end in the object.
  Scan scan = MakeScene();
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  const int pole_col = box.x + box.width / 2 + (3 - (box.x + box.width / 2) % 4);
  cv::Mat strokes = Strokes(scan);
  for (int row = box.y; row < box.y + box.height; ++row) {
    scan.range.at<float>(row, pole_col) -= 1.0f;
    scan.point.at<cv::Vec3f>(row, pole_col) =
        scan.direction.at<cv::Vec3f>(row, pole_col) * scan.range.at<float>(row, pole_col);
    scan.color.at<cv::Vec3b>(row, pole_col) = cv::Vec3b(40, 40, 200);
    scan.label.at<int32_t>(row, pole_col) = 2;
    strokes.at<uint8_t>(row, pole_col) = kStrokeBackground;
  }
  const cv::Mat cells = DecimatedCells(scan, 4);
  for (int r = 0; r < cells.rows; ++r)
    for (int c = 0; c < cells.cols; ++c) ASSERT_NE(cells.at<int32_t>(r, c) % scan.cols, pole_col);
  const SegmentResult cut = SegmentObject(scan, strokes, CoarseAbove(30000));
  ASSERT_EQ(cut.coarse_factor, 4);
  EXPECT_EQ(cv::countNonZero(cut.mask & (strokes == kStrokeBackground)), 0);
  EXPECT_GT(ScoreMask(cut.mask, TruthMask(scan), scan.valid).iou, 0.95);
}

TEST(CoarseToFineTest, LargeFactorsGoDownAPyramid) {
  // f = 8: a level of every 4th ray, cut on a level of every 2nd of its rays in turn; each band re-cut is a
  // few rays of its own level wide.
  const Scan scan = MakeScene();
  const cv::Mat strokes = Strokes(scan), truth = TruthMask(scan);
  const SegmentResult full = SegmentObject(scan, strokes, CoarseAbove(0));
  const SegmentResult pyramid = SegmentObject(scan, strokes, CoarseAbove(6000));
  ASSERT_EQ(pyramid.coarse_factor, 8);
  EXPECT_GT(ScoreMask(pyramid.mask, truth, scan.valid).iou, 0.97);
  EXPECT_GT(ScoreMask(pyramid.mask, full.mask).iou, 0.97);
  // The full-resolution band is the outline times (2 · kBandCoarseCells + 2) · 4 rays (band and rim at the
  // lower level's step of 4), not · 8 as one step of 8 would make it.
  const cv::Rect box = cv::boundingRect(truth);
  const int one_step_of_eight =
      2 * (box.width + box.height) * (2 * segment_internal::kBandCoarseCells + 2) * 8;
  EXPECT_LT(pyramid.graph_nodes, one_step_of_eight * 2 / 3);
}

}  // namespace
}  // namespace lidarshop
