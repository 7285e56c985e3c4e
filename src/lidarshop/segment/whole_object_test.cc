// Whole-object growth across an overhang: a part in front of the object that nothing else visible holds.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_eval.h"
#include "lidarshop/segment/segment_test_util.h"
#include "lidarshop/testing/analytic_scan.h"

namespace lidarshop {
namespace {

using segment_test::Block;
using segment_test::HitBlock;

// Blocks on a grey ground plane 1.5 m below the scanner, a beige wall at y = 12 m behind them.
Scan MakeBlocks(const std::vector<Block>& blocks, uint64_t seed) {
  const test_scenes::AnalyticGrid grid{240, 240, -12, 12, -22, 8};
  return test_scenes::MakeAnalyticScan(
      grid,
      [&](const cv::Vec3f& d) {
        test_scenes::RayHit h = test_scenes::WallAndGround(d, 12.0, cv::Vec3b(120, 120, 116));
        for (const Block& block : blocks) {
          const double t = HitBlock(d, block);
          if (t < h.range_m) h = {t, block.rgb, block.label};
        }
        return h;
      },
      0.003, seed);
}

// A brown post 0.4 m tall with a blue box on top that overhangs it by 0.2 m towards the scanner. (Tops are kept
// 0.9 m or more below the scanner: a face seen at over ~80° incidence steps by more than the growth's depth
// continuity from row to row.)
const Block kPost = {{-0.05, 4.95, -1.5}, {0.05, 5.05, -1.1}, cv::Vec3b(112, 82, 52), 1};
const Block kBoxOnPost = {{-0.15, 4.75, -1.1}, {0.15, 5.25, -0.9}, cv::Vec3b(40, 60, 170), 1};

// A short vertical object stroke on the post (the middle of the object's cells 3/4 of the way down) and a background stroke on the ground to the left.
cv::Mat StrokeOnPost(const Scan& scan) {
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  // The post's column: the middle of the label-1 cells in the row 3/4 down the object.
  const cv::Rect object = cv::boundingRect(scan.label == 1);
  const int row = object.y + 3 * object.height / 4;
  std::vector<int> cols;
  for (int c = 0; c < scan.cols; ++c)
    if (scan.label.at<int32_t>(row, c) == 1) cols.push_back(c);
  const int middle = cols[cols.size() / 2];
  cv::line(strokes, cv::Point(middle, row - 8), cv::Point(middle, row + 8), cv::Scalar(kStrokeObject), 2);
  cv::line(strokes, cv::Point(5, scan.rows - 8), cv::Point(30, scan.rows - 8), cv::Scalar(kStrokeBackground),
           2);
  return strokes;
}

TEST(WholeObjectTest, ABoxOverhangingItsPostJoinsAStrokeOnThePost) {
  const Scan scan = MakeBlocks({kPost, kBoxOnPost}, 3);
  const cv::Mat truth = scan.label == 1;
  const cv::Mat strokes = StrokeOnPost(scan);
  SegmentOptions options;
  options.whole_object.join_overhangs = false;
  const MaskScores without = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  options.whole_object.join_overhangs = true;
  const MaskScores with = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  EXPECT_LT(without.iou, 0.7);  // the post alone: the box is another colour and a depth step away
  EXPECT_GT(with.iou, 0.95) << "precision " << with.precision << " recall " << with.recall;
}

TEST(WholeObjectTest, APostUnderABoxThatOverhangsItJoinsAStrokeOnTheBox) {
  // Issue 30, class 1: the box overhangs its post by 0.2 m towards the scanner, which looks down on it, so the
  // box's front edge hides the post's top: in the grid the post meets the box across a 0.2 m depth step, in
  // space it touches the box's underside. Stroked on the box, the post is a closed part behind it, standing on
  // the ground.
  const Scan scan = MakeBlocks({kPost, kBoxOnPost}, 3);
  const cv::Mat truth = scan.label == 1;
  cv::Mat box_cells = truth.clone();
  for (int r = 0; r < scan.rows; ++r)
    for (int c = 0; c < scan.cols; ++c)
      if (scan.point.at<cv::Vec3f>(r, c)[2] < -1.08f) box_cells.at<uint8_t>(r, c) = 0;
  const cv::Rect box = cv::boundingRect(box_cells);
  ASSERT_GT(box.area(), 50);
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int row = box.y + box.height / 3;
  cv::line(strokes, cv::Point(box.x + box.width / 3, row), cv::Point(box.x + 2 * box.width / 3, row),
           cv::Scalar(kStrokeObject), 1);
  cv::line(strokes, cv::Point(5, scan.rows - 8), cv::Point(30, scan.rows - 8), cv::Scalar(kStrokeBackground),
           2);
  SegmentOptions options;
  options.whole_object.join_steps = false;
  const MaskScores without = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  options.whole_object.join_steps = true;
  const MaskScores with = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  EXPECT_LT(without.recall, 0.9);  // the box alone
  EXPECT_GT(with.iou, 0.95) << "precision " << with.precision << " recall " << with.recall;
}

TEST(WholeObjectTest, ThePostUnderABoxJoinsOnRandomScenes) {
  // Issue 30, random seeds 12 and 43 (segment_eval --random-seeds): a box on a square post, stroked on the box.
  // The post is a closed part behind the box across a depth step, but its grid normals turn by more than
  // max_crease_deg (45°) between neighbouring cells (the post's corner, its top under the box), which split
  // it into open pieces: it stayed out (IoU 0.635, 0.681). Within a closed part a wider crease is allowed.
  for (uint64_t seed : {12u, 43u}) {
    const segment_test::RandomEvalCase c = segment_test::MakeRandomEvalCase(seed);
    const Scan& scan = c.scan;
    const cv::Mat &truth = c.truth, &strokes = c.strokes;
    SegmentOptions options;
    options.whole_object.join_max_crease_deg = options.whole_object.max_crease_deg;
    EXPECT_LT(ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid).iou, 0.7)
        << "seed " << seed;
    const MaskScores with = ScoreMask(SegmentObject(scan, strokes, SegmentOptions()).mask, truth, scan.valid);
    EXPECT_GT(with.iou, 0.95) << "seed " << seed << ": precision " << with.precision << " recall "
                              << with.recall;
  }
}

TEST(WholeObjectTest, EveryLegUnderATableTopThatOverhangsThemJoins) {
  // Three closed parts across a depth step under one top: the growth joins them in one pass over the region
  // (each part explored once), and every one of them, not only the first found.
  const double xs[3] = {-0.35, 0.0, 0.35};
  std::vector<Block> blocks = {{{-0.45, 4.75, -1.1}, {0.45, 5.25, -0.9}, cv::Vec3b(40, 60, 170), 1}};
  for (int i = 0; i < 3; ++i)
    blocks.push_back({{xs[i] - 0.05, 4.95, -1.5}, {xs[i] + 0.05, 5.05, -1.1}, cv::Vec3b(112, 82, 52), 2 + i});
  const Scan scan = MakeBlocks(blocks, 5);
  const cv::Mat top = scan.label == 1;
  const cv::Mat grown = GrowWholeObject(scan, top, cv::Mat());
  for (int leg = 2; leg <= 4; ++leg) {
    const cv::Mat cells = (scan.label == leg) & (scan.valid != 0);
    const int total = cv::countNonZero(cells);
    ASSERT_GT(total, 20) << "leg " << leg;
    EXPECT_GT(cv::countNonZero(grown & cells), 0.8 * total) << "leg " << leg;  // less its foot
  }
  // Nothing but the table: the ground and the wall stay out.
  const cv::Mat table = (scan.label >= 1) & (scan.label <= 4);
  EXPECT_LT(cv::countNonZero(grown & ~table), 0.02 * cv::countNonZero(table));
}

TEST(WholeObjectTest, APartInFrontThatStandsOnTheGroundDoesNotJoin) {
  // A crate on the ground in front of the post's foot: in front of the object, but the ground holds it.
  const Block crate = {{-0.25, 4.4, -1.5}, {0.25, 4.7, -1.25}, cv::Vec3b(40, 60, 170), 2};
  const Scan scan = MakeBlocks({kPost, crate}, 5);
  const cv::Mat post = scan.label == 1;
  const cv::Mat grown = GrowWholeObject(scan, post, cv::Mat());
  EXPECT_EQ(cv::countNonZero(grown & (scan.label == 2)), 0);
  // A smaller crate held off the ground (nothing visible holds it but the post) joins.
  const Block floating = {{-0.12, 4.4, -1.35}, {0.12, 4.7, -1.25}, cv::Vec3b(40, 60, 170), 2};
  const Scan lifted = MakeBlocks({kPost, floating}, 5);
  const cv::Mat lifted_grown = GrowWholeObject(lifted, lifted.label == 1, cv::Mat());
  EXPECT_EQ(cv::countNonZero(lifted_grown & (lifted.label == 2)), cv::countNonZero(lifted.label == 2));
}

TEST(WholeObjectTest, TheLowerCrateOfAStackJoinsTheBoxOnTopOfIt) {
  // Issue 30, class 1: a box standing on a crate four times its size, the growth started from the box. The crate
  // is in front of the box across a depth step (its top face, seen at grazing incidence, between them) and
  // stands on the ground; the box's lowest points lie on its top.
  const Block crate = {{-0.4, 4.6, -1.5}, {0.4, 5.2, -1.0}, cv::Vec3b(60, 160, 160), 1};
  const Block box = {{-0.2, 4.8, -1.0}, {0.2, 5.0, -0.75}, cv::Vec3b(150, 110, 60), 2};
  const Scan scan = MakeBlocks({crate, box}, 13);
  const cv::Mat crate_cells = (scan.label == 1) & (scan.valid != 0);
  ASSERT_GT(cv::countNonZero(crate_cells), 3 * cv::countNonZero(scan.label == 2));
  WholeObjectOptions options;
  options.join_rests_on = false;
  EXPECT_LT(cv::countNonZero(GrowWholeObject(scan, scan.label == 2, cv::Mat(), options) & crate_cells),
            cv::countNonZero(crate_cells) / 4);
  options.join_rests_on = true;
  const cv::Mat grown = GrowWholeObject(scan, scan.label == 2, cv::Mat(), options);
  EXPECT_GT(cv::countNonZero(grown & crate_cells), 0.95 * cv::countNonZero(crate_cells));
  EXPECT_LT(cv::countNonZero(grown & (scan.label == 0)), 0.02 * cv::countNonZero(crate_cells));  // no ground
}

TEST(WholeObjectTest, AThreeCentimetreBasePlateIsNotTheGround) {
  // Issue 30, random seeds 4 and 86: a traffic cone's base plate, 3 cm thick, on the ground. With support planes
  // 3 cm thick the plate's top was ground and the plate stayed out (IoU 0.66); the ground's own points lie
  // within a few millimetres of its plane (range noise σ 3 mm), so 2.5 cm still holds all of it.
  const Block plate = {{-0.3, 4.7, -1.5}, {0.3, 5.3, -1.47}, cv::Vec3b(90, 90, 95), 1};
  const Block cone = {{-0.12, 4.88, -1.47}, {0.12, 5.12, -0.95}, cv::Vec3b(230, 90, 20), 2};
  const Scan scan = MakeBlocks({plate, cone}, 17);
  const cv::Mat plate_cells = (scan.label == 1) & (scan.valid != 0);
  ASSERT_GT(cv::countNonZero(plate_cells), 50);
  WholeObjectOptions options;
  options.support_distance_m = 0.03;
  EXPECT_LT(cv::countNonZero(GrowWholeObject(scan, scan.label == 2, cv::Mat(), options) & plate_cells),
            cv::countNonZero(plate_cells) / 2);
  const cv::Mat grown = GrowWholeObject(scan, scan.label == 2, cv::Mat());
  EXPECT_GT(cv::countNonZero(grown & plate_cells), 0.8 * cv::countNonZero(plate_cells));  // 84 % here
  EXPECT_LT(cv::countNonZero(grown & (scan.label == 0)),
            0.02 * cv::countNonZero(scan.label > 0));  // no ground
}

TEST(WholeObjectTest, APlateInFrontOfTheObjectWithTheObjectAllAroundItDoesNotJoin) {
  // A wide board on the ground (the object) and a small plate hanging 0.3 m in front of its middle: in front,
  // held by nothing visible, but the object lies all around it: an occluder, not a part. Lifted to the board's
  // top edge, so that it meets the board along one side only, it joins.
  const Block board = {{-0.8, 5.0, -1.5}, {0.8, 5.1, -0.7}, cv::Vec3b(40, 60, 170), 1};
  const Block plate = {{-0.1, 4.7, -1.2}, {0.1, 4.72, -1.0}, cv::Vec3b(200, 30, 30), 2};
  const Scan scan = MakeBlocks({board, plate}, 11);
  const cv::Mat grown = GrowWholeObject(scan, scan.label == 1, cv::Mat());
  EXPECT_EQ(cv::countNonZero(grown & (scan.label == 2)), 0);  // all of it with overhang_max_contact = 1
  Block on_top = plate;
  on_top.lo[2] = -0.72;
  on_top.hi[2] = -0.42;
  const Scan lifted = MakeBlocks({board, on_top}, 11);
  const cv::Mat lifted_grown = GrowWholeObject(lifted, lifted.label == 1, cv::Mat());
  EXPECT_EQ(cv::countNonZero(lifted_grown & (lifted.label == 2)), cv::countNonZero(lifted.label == 2));
}

TEST(WholeObjectTest, GrowthFromAWholeObjectAddsNoSupportAlongItsFoot) {
  // A crate standing on the ground, seen slightly from the side (so its foot is an outline on the ground with
  // corners): the ground cells along the foot have normals that mix in the crate's faces.
  const Block crate = {{-0.55, 4.6, -1.5}, {0.15, 5.2, -0.9}, cv::Vec3b(40, 60, 170), 1};
  const Scan scan = MakeBlocks({crate}, 7);
  const cv::Mat truth = scan.label == 1;
  const cv::Mat grown = GrowWholeObject(scan, truth, cv::Mat());
  EXPECT_EQ(cv::countNonZero(grown & ~truth), 0);  // 10 cells with support_max_tilt_deg = 45
}

TEST(WholeObjectTest, SupportSurfaceCellsAreTheGroundTheCutTookAtTheFootNotTheObject) {
  // What step 1 hands step 3 when the depth cut took a fringe of ground at the crate's foot: the fringe is
  // support (left free for the colour cut), the crate is not.
  const Block crate = {{-0.55, 4.6, -1.5}, {0.15, 5.2, -0.9}, cv::Vec3b(40, 60, 170), 1};
  const Scan scan = MakeBlocks({crate}, 7);
  const cv::Mat truth = scan.label == 1;
  cv::Mat fringe;
  cv::dilate(truth, fringe, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  fringe &= ~truth;
  fringe &= scan.label == 0;  // the ground only, not the wall
  const cv::Rect box = cv::boundingRect(truth);
  fringe(cv::Rect(0, 0, scan.cols, box.y + box.height / 2)) = 0;  // along the foot
  ASSERT_GT(cv::countNonZero(fringe), 20);
  const cv::Mat support = SupportSurfaceCells(scan, truth | fringe);
  EXPECT_GT(cv::countNonZero(support & fringe), cv::countNonZero(fringe) * 3 / 4)
      << cv::countNonZero(support & fringe) << " of " << cv::countNonZero(fringe);
  // Of the crate, only cells within a few centimetres of the ground can be taken for it (its lowest row, whose
  // normals mix in the ground's).
  int crate_support_above_foot = 0;
  for (int r = 0; r < scan.rows; ++r)
    for (int c = 0; c < scan.cols; ++c)
      crate_support_above_foot += support.at<uint8_t>(r, c) && truth.at<uint8_t>(r, c) &&
                                  scan.point.at<cv::Vec3f>(r, c)[2] > -1.5f + 0.05f;
  EXPECT_EQ(crate_support_above_foot, 0);
}

}  // namespace
}  // namespace lidarshop
