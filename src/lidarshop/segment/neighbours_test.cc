#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/segment/segment.h"
#include "lidarshop/testing/analytic_scan.h"

namespace lidarshop {
namespace {

struct Pillar {
  double x, y, radius;  // axis position and radius, metres (the axis is vertical, z from -1.5 to 0)
  cv::Vec3b rgb;
  int label;
};

// A hand-made scan (analytic ray casting): vertical pillars 1.5 m tall standing on a grey ground plane 1.5 m
// below the scanner, a beige wall at y = 15 m behind them.
Scan MakePillars(const std::vector<Pillar>& pillars, uint64_t seed) {
  const test_scenes::AnalyticGrid grid{180, 360, -14, 14, -24, 8};
  return test_scenes::MakeAnalyticScan(
      grid,
      [&](const cv::Vec3f& d) {
        test_scenes::RayHit h = test_scenes::WallAndGround(d, 15.0, cv::Vec3b(130, 130, 126));
        for (const Pillar& pillar : pillars) {
          const double a = d[0] * d[0] + d[1] * d[1], b = -2 * (d[0] * pillar.x + d[1] * pillar.y),
                       c = pillar.x * pillar.x + pillar.y * pillar.y - pillar.radius * pillar.radius;
          const double discriminant = b * b - 4 * a * c;
          if (discriminant < 0) continue;
          const double t = (-b - std::sqrt(discriminant)) / (2 * a);
          if (t >= h.range_m || t * d[2] < -1.5 || t * d[2] > 0) continue;
          h = {t, pillar.rgb, pillar.label};
        }
        return h;
      },
      0.004, seed);
}

// A short object stroke across the middle of label 1, a background stroke on the ground to the left.
cv::Mat StrokeOnLabelOne(const Scan& scan) {
  const cv::Rect box = cv::boundingRect(scan.label == 1);
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Point centre(box.x + box.width / 2, box.y + box.height / 2);
  cv::line(strokes, centre - cv::Point(box.width / 5, 0), centre + cv::Point(box.width / 5, 0),
           cv::Scalar(kStrokeObject), 2);
  cv::line(strokes, cv::Point(5, scan.rows - 8), cv::Point(30, scan.rows - 8), cv::Scalar(kStrokeBackground),
           2);
  return strokes;
}

// Two pillars touching side by side at the same range, in different colours.
const std::vector<Pillar> kTouchingPair = {{-0.25, 5.0, 0.25, cv::Vec3b(180, 40, 40), 1},
                                           {0.25, 5.0, 0.25, cv::Vec3b(40, 70, 170), 2}};

TEST(NeighboursTest, CrevicesRunAlongTheContactOfTouchingBodiesOnly) {
  const Scan scan = MakePillars(kTouchingPair, 3);
  const cv::Mat crevice = CreviceEdges(scan, cv::Rect(0, 0, scan.cols, scan.rows), WholeObjectOptions());
  // Every flagged edge lies on the contact: within three columns and a row of a cell whose right neighbour is
  // the other pillar (at the foot, the crevice runs a row into the ground's wedge), and most rows of the pair
  // have one.
  int rows_with_crevice = 0, edges_off_contact = 0;
  const cv::Rect pair = cv::boundingRect(scan.label >= 1);
  for (int r = 0; r < scan.rows; ++r) {
    bool found = false;
    for (int c = 0; c + 1 < scan.cols; ++c) {
      if (!crevice.at<uint8_t>(r, c)) continue;
      bool near_contact = false;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -3; dc <= 3; ++dc) {
          const int rr = std::clamp(r + dr, 0, scan.rows - 1), cc = std::clamp(c + dc, 0, scan.cols - 2);
          near_contact |= scan.label.at<int32_t>(rr, cc) == 1 && scan.label.at<int32_t>(rr, cc + 1) == 2;
        }
      }
      edges_off_contact += !near_contact;
      found |= near_contact;
    }
    rows_with_crevice += found;
  }
  EXPECT_EQ(edges_off_contact, 0);
  EXPECT_GT(rows_with_crevice, 0.8 * pair.height);
}

// The label-1 pillar cut from StrokeOnLabelOne's strokes without and with the separation of touching
// neighbours, scored against its true cells.
struct WithoutAndWith {
  MaskScores without, with;
  SegmentResult result;  // with the separation
};
WithoutAndWith SegmentWithoutAndWithSeparation(const Scan& scan) {
  const cv::Mat truth = scan.label == 1;
  const cv::Mat strokes = StrokeOnLabelOne(scan);
  SegmentOptions options;
  options.whole_object.separate_touching = false;
  WithoutAndWith out;
  out.without = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid);
  options.whole_object.separate_touching = true;
  out.result = SegmentObject(scan, strokes, options);
  out.with = ScoreMask(out.result.mask, truth, scan.valid);
  return out;
}

TEST(NeighboursTest, APillarTouchingTheStrokedOneIsANeighbourNotAPart) {
  const Scan scan = MakePillars(kTouchingPair, 5);
  const auto [without, with, result] = SegmentWithoutAndWithSeparation(scan);
  EXPECT_LT(without.iou, 0.7);  // the depth cut takes both pillars, and the colour cut keeps them
  EXPECT_GT(with.iou, 0.95) << "precision " << with.precision << " recall " << with.recall;
  // The neighbour is inferred background, so no later step takes it back.
  EXPECT_GT(cv::countNonZero(result.inferred_background & (scan.label == 2)),
            cv::countNonZero(scan.label == 2) / 2);
}

TEST(NeighboursTest, APairSeenObliquelyIsStillSeparated) {
  // The pair 0.8 m to the side (9° off the scanner's line of sight to the contact): the crevice wanders by a
  // cell from row to row and gains a small depth step; the two sides must not meet through its zigzag.
  std::vector<Pillar> pair = kTouchingPair;
  for (Pillar& pillar : pair) pillar.x += 0.8;
  const Scan scan = MakePillars(pair, 9);
  const auto [without, with, result] = SegmentWithoutAndWithSeparation(scan);
  EXPECT_LT(without.iou, 0.7);
  EXPECT_GT(with.iou, 0.95) << "precision " << with.precision << " recall " << with.recall;
}

TEST(NeighboursTest, ASingleBodyOnTheGroundHasNoNeighbour) {
  // One pillar and, a metre to its right, another one: the ground between them meets each at an open crease.
  const Scan scan = MakePillars(
      {{-0.25, 5.0, 0.25, cv::Vec3b(180, 40, 40), 1}, {0.9, 5.0, 0.25, cv::Vec3b(180, 40, 40), 2}}, 7);
  cv::Mat around_truth;
  cv::dilate(scan.label == 1, around_truth, cv::Mat(), cv::Point(-1, -1), 6);
  const cv::Mat object_cells = StrokeOnLabelOne(scan) == kStrokeObject;
  EXPECT_EQ(cv::countNonZero(TouchingNeighbours(scan, around_truth, object_cells)), 0);
}

}  // namespace
}  // namespace lidarshop
