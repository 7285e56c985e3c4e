#include "lidarshop/fill/remove.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A red box in front of a wall on grass; strokes on the box and on the wall / ground around it.
constexpr const char* kScene = R"({
  "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-20, 20], "elevation_deg": [-20, 10], "columns": 160,
              "rows": 120, "max_range": 40, "seed": 7},
  "objects": [
    {"primitive": "plane", "size": [40, 40], "translate": [0, 15, 0], "label": 0, "texture": "grass"},
    {"primitive": "wall", "size": [12, 0.3, 2.5], "translate": [0, 7, 0], "label": 2, "color": [200, 200, 190]},
    {"primitive": "box", "size": [0.8, 0.5, 1.2], "translate": [0.2, 4.5, 0.6], "label": 1, "color": [200, 30, 30]}
  ]
})";

struct RemoveCase {
  Scan scan, truth;
  cv::Mat strokes;
};

RemoveCase MakeRemoveCase() {
  const SceneDescription scene = ParseScene(kScene, "test scene", ".");
  SceneDescription without = scene;
  std::erase_if(without.objects, [](const SceneObject& o) { return o.label == 1; });
  RemoveCase c{SynthesizeScan(scene), SynthesizeScan(without), {}};
  // Object stroke: the box's cells eroded; background stroke: a ring of cells well outside it.
  const cv::Mat box = (c.scan.label == 1) & (c.scan.valid != 0);
  cv::Mat inner, outer;
  cv::erode(box, inner, cv::Mat(), cv::Point(-1, -1), 3);
  cv::dilate(box, outer, cv::Mat(), cv::Point(-1, -1), 8);
  cv::Mat ring;
  cv::dilate(outer, ring, cv::Mat(), cv::Point(-1, -1), 2);
  ring &= ~outer;
  c.strokes = cv::Mat(c.scan.rows, c.scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  c.strokes.setTo(kStrokeObject, inner);
  c.strokes.setTo(kStrokeBackground, ring & (c.scan.valid != 0));
  return c;
}

TEST(RemoveObject, CutsTheBoxAndFillsBehindIt) {
  const RemoveCase c = MakeRemoveCase();
  const RemoveResult removed = RemoveObject(c.scan, c.strokes);
  const cv::Mat box = (c.scan.label == 1) & (c.scan.valid != 0);
  EXPECT_EQ(cv::countNonZero(box & ~removed.hole), 0);  // every box cell is in the hole
  // No box label survives; the fill is close to the scan without the box.
  EXPECT_EQ(cv::countNonZero(removed.fill.scan.label == 1), 0);
  const FillMetrics m = MeasureFill(removed.fill.scan, c.truth, removed.hole);
  EXPECT_LT(m.range_rmse_mm, 100.0);
  EXPECT_TRUE(removed.behind.valid.empty());
}

TEST(RemoveObject, KeepObjectGivesTheFillAsALayerBehindTheObjectOnly) {
  const RemoveCase c = MakeRemoveCase();
  RemoveOptions options;
  options.keep_object = true;
  const RemoveResult removed = RemoveObject(c.scan, c.strokes, options);
  ASSERT_FALSE(removed.behind.valid.empty());
  const cv::Mat behind = removed.behind.valid != 0;
  EXPECT_GT(cv::countNonZero(behind), 0);
  EXPECT_EQ(cv::countNonZero(behind & (removed.cut.mask == 0)), 0);  // only behind the object's cells
  EXPECT_EQ(cv::countNonZero(behind & (removed.behind.synthesized == 0)), 0);
  // Behind the box means farther along the same ray; where the cut took a little of the ground at the
  // box's foot, the layer is that ground again (the planes around the hole place it there).
  int box_cells = 0, well_behind = 0;
  for (int y = 0; y < c.scan.rows; ++y) {
    for (int x = 0; x < c.scan.cols; ++x) {
      if (!behind.at<uint8_t>(y, x)) continue;
      const float layer = removed.behind.range.at<float>(y, x), seen = c.scan.range.at<float>(y, x);
      if (c.scan.label.at<int32_t>(y, x) == 1) {
        // (At the box's foot the ground it stands on is hidden only millimetres behind its face.)
        EXPECT_GT(layer, seen - 0.01f) << "row " << y << ", col " << x;
        ++box_cells;
        well_behind += layer > seen + 0.1f;
      } else {
        EXPECT_NEAR(layer, seen, 0.05f) << "row " << y << ", col " << x;
      }
    }
  }
  EXPECT_GT(box_cells, 100);
  EXPECT_GT(well_behind, box_cells * 3 / 4);
}

TEST(RemoveObjectWindow, ItsFillAppliedAndItsLayerBehindAreRemoveObjects) {
  const RemoveCase c = MakeRemoveCase();
  RemoveOptions options;
  options.keep_object = true;
  options.fill.window_min_margin_cells = 8;  // a window smaller than this small scan
  options.fill.window_margin = 0.5;
  options.fill.window_min_known_ratio = 1.0;
  const RemoveResult whole = RemoveObject(c.scan, c.strokes, options);
  const RemoveResult windowed = RemoveObjectWindow(c.scan, c.strokes, options);
  const cv::Rect window = windowed.fill.Window();
  ASSERT_LT(window.area(), c.scan.rows * c.scan.cols);
  EXPECT_EQ(windowed.fill.scan.range.size(), window.size());
  EXPECT_EQ(cv::countNonZero(windowed.hole != whole.hole), 0);
  Scan applied = Clone(c.scan);
  ApplyFill(windowed.fill, &applied);
  EXPECT_EQ(cv::norm(applied.range, whole.fill.scan.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(applied.synthesized, whole.fill.scan.synthesized, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(applied.color.reshape(1), whole.fill.scan.color.reshape(1), cv::NORM_INF), 0.0);
  // The layer behind is the same scan either way: the window's filled object cells, no return elsewhere.
  EXPECT_GT(cv::countNonZero(whole.behind.valid), 0);
  EXPECT_EQ(cv::norm(windowed.behind.valid, whole.behind.valid, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(windowed.behind.range, whole.behind.range, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(windowed.behind.synthesized, whole.behind.synthesized, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(windowed.behind.direction.reshape(1), whole.behind.direction.reshape(1), cv::NORM_INF),
            0.0);
}

TEST(RemoveObject, EnclosedNoReturnCellsJoinTheHole) {
  // A ring-shaped object with a no-return cell inside it, one inside its ring band, and one outside.
  cv::Mat mask(9, 9, CV_8U, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(2, 2, 5, 5), cv::Scalar(255), 1);
  cv::Mat valid(9, 9, CV_8U, cv::Scalar(255));
  valid.at<uint8_t>(4, 4) = 0;  // enclosed
  valid.at<uint8_t>(0, 0) = 0;  // outside, reachable from the border
  const cv::Mat enclosed = EnclosedNoReturnCells(mask, valid);
  EXPECT_EQ(cv::countNonZero(enclosed), 1);
  EXPECT_EQ(enclosed.at<uint8_t>(4, 4), 255);
}

TEST(RemoveObject, BadOptionsAndStrokes) {
  const RemoveCase c = MakeRemoveCase();
  RemoveOptions options;
  options.margin_cells = -1;
  EXPECT_THROW(RemoveObject(c.scan, c.strokes, options), OptionsError);
  EXPECT_THROW(RemoveObject(c.scan, cv::Mat(3, 3, CV_8U, cv::Scalar(0))), InputError);
}

}  // namespace
}  // namespace lidarshop
