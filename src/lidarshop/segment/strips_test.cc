// Strips along the scene (TrimStrips): a kerb's face behind a sign's post.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_test_util.h"
#include "lidarshop/testing/analytic_scan.h"

namespace lidarshop {
namespace strips_test {  // named: the tests are compiled in unity batches with whole_object_test's blocks
namespace {

using segment_test::Block;
using segment_test::HitBlock;

// Blocks on a grey ground 1.5 m below the scanner before a wall at y = 14 m, 0.2° between rays (3.5 cm at
// 10 m: a 0.15 m kerb is 4 rows tall, as a kerb at 25 m in a scan of 400 x 300 rays).
Scan MakeScene(const std::vector<Block>& blocks, uint64_t seed) {
  const test_scenes::AnalyticGrid grid{150, 250, -25, 25, -22, 8};
  return test_scenes::MakeAnalyticScan(
      grid,
      [&](const cv::Vec3f& d) {
        test_scenes::RayHit h = test_scenes::WallAndGround(d, 14.0, cv::Vec3b(120, 120, 116));
        for (const Block& block : blocks) {
          const double t = HitBlock(d, block);
          if (t < h.range_m) h = {t, block.rgb, block.label};
        }
        return h;
      },
      0.003, seed);
}

// An object stroke across the middle of the cells of `label` in their upper third, a background stroke on the
// ground near the bottom.
cv::Mat Strokes(const Scan& scan, int label) {
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Rect box = cv::boundingRect(scan.label == label);
  const int row = box.y + box.height / 6;
  cv::line(strokes, cv::Point(box.x + box.width / 3, row), cv::Point(box.x + 2 * box.width / 3, row),
           cv::Scalar(kStrokeObject), 1);
  cv::line(strokes, cv::Point(box.x, scan.rows - 8), cv::Point(box.br().x, scan.rows - 8),
           cv::Scalar(kStrokeBackground), 1);
  return strokes;
}

// A grey sign on a post at 10 m, standing on the ground 5 cm before a kerb's olive front face 0.15 m tall that
// runs across the picture, the pavement behind it up to the wall.
const Block kSign = {{-0.3, 9.9, -0.5}, {0.3, 10.0, -0.1}, cv::Vec3b(90, 90, 96), 1};
const Block kPost = {{-0.06, 9.94, -1.5}, {0.06, 10.0, -0.5}, cv::Vec3b(90, 90, 96), 1};
const Block kKerb = {{-40, 10.05, -1.5}, {40, 14.0, -1.35}, cv::Vec3b(80, 74, 30), 2};

TEST(StripsTest, AKerbBehindASignsPostIsNotTheSign) {
  const Scan scan = MakeScene({kSign, kPost, kKerb}, 3);
  const cv::Mat truth = scan.label == 1;
  const cv::Mat strokes = Strokes(scan, 1);
  SegmentOptions options;
  // Support planes 3 cm thick, as when this was written: at 2.5 cm (the default since) the cuts no longer take
  // this kerb, and the test is about the strips.
  options.whole_object.support_distance_m = 0.03;
  options.whole_object.strip_max_cells = 0;
  const MaskScores without = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  options.whole_object.strip_max_cells = SegmentOptions().whole_object.strip_max_cells;
  const MaskScores with = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  EXPECT_LT(without.precision, 0.7) << "IoU " << without.iou;  // the kerb across the picture
  EXPECT_GT(with.iou, 0.95) << "precision " << with.precision << " recall " << with.recall;
}

TEST(StripsTest, AThinPartAboveTheStrokedOneStays) {
  // A table's top seen edge-on (3 rows) on one leg, stroked on the leg: a long thin part, but not at its foot.
  const cv::Mat mask = cv::Mat::zeros(100, 200, CV_8U), strokes = cv::Mat::zeros(100, 200, CV_8U);
  mask(cv::Rect(20, 30, 160, 3)) = 255;  // the top
  mask(cv::Rect(20, 33, 4, 40)) = 255;   // the stroked leg
  strokes(cv::Rect(21, 40, 2, 10)) = 255;
  const Scan scan = MakeScan(100, 200, /*with_color=*/false);
  EXPECT_EQ(cv::countNonZero(TrimStrips(scan, mask, strokes) != mask), 0);
  // The same strip at the leg's foot runs along the scene: dropped beyond the leg.
  cv::Mat at_foot = cv::Mat::zeros(100, 200, CV_8U);
  at_foot(cv::Rect(20, 70, 160, 3)) = 255;
  at_foot(cv::Rect(20, 30, 4, 40)) = 255;
  const cv::Mat trimmed = TrimStrips(scan, at_foot, strokes);
  EXPECT_EQ(cv::countNonZero(trimmed(cv::Rect(40, 0, 160, 100))), 0);
  EXPECT_EQ(cv::countNonZero(trimmed(cv::Rect(20, 30, 4, 40)) != 255), 0);  // the leg stays
}

}  // namespace
}  // namespace strips_test
}  // namespace lidarshop
