// The cuts' window (SegmentOptions::window_margin_cells): a cut that stays inside its window is the cut of the
// whole scan, the window grows while the cut reaches its edge, up to the whole scan, and a session's
// refinements give what they give without a window.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_test_util.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using segment_test::MakeBoxOnGround;
using segment_test::TruthMask;

// A scan much larger than the box (the box is about a fifth of it across).
Scan MakeWindowScene() { return MakeBoxOnGround(240, 400, cv::Vec3b(118, 138, 112), 11); }

// An object stroke across the box's middle third and a background stroke on the wall just above the box:
// both inside the box's neighbourhood, so a small margin gives a window much smaller than the scan.
cv::Mat NearStrokes(const Scan& scan) {
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  const cv::Point c(box.x + box.width / 2, box.y + box.height / 2);
  cv::line(strokes, c - cv::Point(box.width / 6, 0), c + cv::Point(box.width / 6, 0),
           cv::Scalar(kStrokeObject), 2);
  cv::line(strokes, cv::Point(c.x - box.width / 6, box.y - 6), cv::Point(c.x + box.width / 6, box.y - 6),
           cv::Scalar(kStrokeBackground), 2);
  return strokes;
}

SegmentOptions WithMargin(int margin_cells, SegmentMethod method = SegmentMethod::kTwoStep) {
  SegmentOptions options;
  options.method = method;
  options.window_margin_cells = margin_cells;
  return options;
}

int DifferingCells(const cv::Mat& a, const cv::Mat& b) { return cv::countNonZero(a != b); }

int64_t WindowCells(const SegmentResult& r) { return int64_t{r.window_rows} * r.window_cols; }

TEST(SegmentWindowTest, AWindowHoldingTheObjectGivesTheWholeScanCut) {
  const Scan scan = MakeWindowScene();
  const cv::Mat strokes = NearStrokes(scan);
  for (SegmentMethod method :
       {SegmentMethod::kTwoStep, SegmentMethod::kDepth, SegmentMethod::kColor, SegmentMethod::kRgbd}) {
    const SegmentResult whole = SegmentObject(scan, strokes, WithMargin(0, method));
    const SegmentResult windowed = SegmentObject(scan, strokes, WithMargin(60, method));
    EXPECT_EQ(WindowCells(whole), int64_t{scan.rows} * scan.cols) << ToString(method);
    EXPECT_EQ(whole.window_growths, 0);
    // The window is much smaller than the scan, and the masks are identical cell by cell.
    EXPECT_LT(WindowCells(windowed), int64_t{scan.rows} * scan.cols / 2) << ToString(method);
    EXPECT_LT(windowed.graph_nodes, whole.graph_nodes) << ToString(method);
    EXPECT_GT(whole.object_cells, 0) << ToString(method);
    EXPECT_EQ(DifferingCells(windowed.mask, whole.mask), 0) << ToString(method);
    EXPECT_EQ(windowed.object_cells, whole.object_cells) << ToString(method);
    if (method == SegmentMethod::kTwoStep) {
      EXPECT_EQ(DifferingCells(windowed.step1_mask, whole.step1_mask), 0);
      EXPECT_EQ(DifferingCells(windowed.inferred_background, whole.inferred_background), 0);
      EXPECT_GT(ScoreMask(windowed.mask, TruthMask(scan), scan.valid).iou, 0.9);
    }
  }
}

TEST(SegmentWindowTest, TheWindowGrowsUntilTheObjectIsInside) {
  const Scan scan = MakeWindowScene();
  const cv::Mat strokes = NearStrokes(scan);
  const SegmentResult whole = SegmentObject(scan, strokes, WithMargin(0));
  // A margin of 2 cells: the first window holds the strokes and little more, the box reaches beyond it.
  const SegmentResult grown = SegmentObject(scan, strokes, WithMargin(2));
  EXPECT_GT(grown.window_growths, 0);
  const cv::Rect truth_box = cv::boundingRect(TruthMask(scan));
  const cv::Rect window(grown.window_col, grown.window_row, grown.window_cols, grown.window_rows);
  EXPECT_EQ(truth_box & window, truth_box);
  EXPECT_LT(WindowCells(grown), int64_t{scan.rows} * scan.cols);
  EXPECT_EQ(DifferingCells(grown.mask, whole.mask), 0);
  EXPECT_GT(ScoreMask(grown.mask, TruthMask(scan), scan.valid).iou, 0.9);
}

TEST(SegmentWindowTest, TheWindowGrowsToTheWholeScanForAnObjectAcrossIt) {
  // The wall is the object: it runs across the whole scan, so every window but the whole scan is too small.
  const Scan scan = MakeWindowScene();
  const cv::Mat wall = (scan.label == 0) & (scan.valid != 0);
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  cv::line(strokes, cv::Point(box.x, box.y - 8), cv::Point(box.x + box.width, box.y - 8),
           cv::Scalar(kStrokeObject), 1);
  cv::line(strokes, cv::Point(box.x + 5, box.y + box.height / 2),
           cv::Point(box.x + box.width - 5, box.y + box.height / 2), cv::Scalar(kStrokeBackground), 1);
  strokes.setTo(kStrokeNone, ((strokes == kStrokeObject) & ~wall) != 0);
  ASSERT_GT(cv::countNonZero(strokes == kStrokeObject), 0);
  for (SegmentMethod method : {SegmentMethod::kColor, SegmentMethod::kRgbd}) {
    const SegmentResult whole = SegmentObject(scan, strokes, WithMargin(0, method));
    const SegmentResult grown = SegmentObject(scan, strokes, WithMargin(4, method));
    // The cut spans the scan from side to side.
    ASSERT_GT(cv::countNonZero(whole.mask.col(0)), 0) << ToString(method);
    ASSERT_GT(cv::countNonZero(whole.mask.col(scan.cols - 1)), 0) << ToString(method);
    EXPECT_GT(grown.window_growths, 1) << ToString(method);
    EXPECT_EQ(grown.window_cols, scan.cols) << ToString(method);
    EXPECT_EQ(DifferingCells(grown.mask, whole.mask), 0) << ToString(method);
  }
}

TEST(SegmentWindowTest, RefinementsGiveWhatTheyGiveOnTheWholeScan) {
  const Scan scan = MakeWindowScene();
  const cv::Mat strokes = NearStrokes(scan);
  SegmentSession whole(scan, WithMargin(0)), windowed(scan, WithMargin(30));
  const SegmentResult a0 = whole.Run(strokes), b0 = windowed.Run(strokes);
  ASSERT_EQ(DifferingCells(a0.mask, b0.mask), 0);
  const cv::Rect first_window(b0.window_col, b0.window_row, b0.window_cols, b0.window_rows);
  ASSERT_LT(first_window.area(), scan.rows * scan.cols / 2);
  // A background stroke across the box's lower part, inside the window: incremental on both.
  const cv::Rect box = cv::boundingRect(TruthMask(scan));
  cv::Mat band(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int band_row = box.y + (3 * box.height) / 4;
  cv::line(band, cv::Point(box.x - 3, band_row), cv::Point(box.x + box.width + 3, band_row),
           cv::Scalar(kStrokeBackground), 1);
  const SegmentResult a1 = whole.Refine(band), b1 = windowed.Refine(band);
  EXPECT_LT(a1.object_cells, a0.object_cells);
  EXPECT_EQ(DifferingCells(a1.mask, b1.mask), 0);
  EXPECT_EQ(b1.window_growths, 0);
  // An object stroke on the wall far beyond the window: the window takes it in and the cut is re-run.
  cv::Mat far(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Mat wall = (scan.valid != 0) & (TruthMask(scan) == 0);
  int far_row = -1;
  for (int row = 0; row < scan.rows && far_row < 0; ++row)
    if (wall.at<uint8_t>(row, 5) != 0 && wall.at<uint8_t>(row, 15) != 0) far_row = row;
  ASSERT_GE(far_row, 0);
  cv::line(far, cv::Point(5, far_row), cv::Point(15, far_row), cv::Scalar(kStrokeObject), 1);
  ASSERT_FALSE(first_window.contains(cv::Point(5, far_row)));
  const SegmentResult a2 = whole.Refine(far), b2 = windowed.Refine(far);
  EXPECT_GT(b2.window_growths, 0);
  EXPECT_TRUE(cv::Rect(b2.window_col, b2.window_row, b2.window_cols, b2.window_rows).contains({5, far_row}));
  EXPECT_EQ(cv::countNonZero((far == kStrokeObject) & (b2.mask == 0)), 0);
  EXPECT_EQ(DifferingCells(a2.mask, b2.mask), 0);
}

TEST(SegmentWindowTest, TheWindowIsAnOptionAndIsReported) {
  const nlohmann::ordered_json options = ToJson(SegmentOptions());
  ASSERT_TRUE(options.contains("window_margin_cells"));
  EXPECT_EQ(options["window_margin_cells"], 128);
  SegmentOptions bad;
  bad.window_margin_cells = -1;
  EXPECT_THROW(bad.Check(), OptionsError);
  const Scan scan = MakeWindowScene();
  const nlohmann::ordered_json result = ToJson(SegmentObject(scan, NearStrokes(scan), WithMargin(60)));
  for (const char* key : {"window_row", "window_col", "window_rows", "window_cols", "window_growths"})
    EXPECT_TRUE(result.contains(key)) << key;
  EXPECT_GT(result["window_rows"].get<int>(), 0);
}

}  // namespace
}  // namespace lidarshop
