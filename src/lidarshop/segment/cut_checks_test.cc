#include "lidarshop/segment/cut_checks.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_eval.h"

namespace lidarshop {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(CutChecksTest, GrowthOfMoreThanThreeTimesTheStrokedPartIsReported) {
  cv::Mat part(100, 100, CV_8U, cv::Scalar(0));
  part(cv::Rect(40, 40, 10, 10)).setTo(255);  // 100 cells
  cv::Mat cut = part.clone();
  cut(cv::Rect(10, 40, 30, 10)).setTo(255);  // 300 cells added: 3 times
  EXPECT_TRUE(CheckCut(cut, part, false).empty());
  cut(cv::Rect(8, 40, 2, 1)).setTo(255);  // 302 cells added
  const std::vector<std::string> warnings = CheckCut(cut, part, false);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("grew 302 cells past the 100 cells"), std::string::npos) << warnings[0];
  // No part to compare with (single-cut methods): no growth check.
  EXPECT_TRUE(CheckCut(cut, cv::Mat(), false).empty());
}

TEST(CutChecksTest, TouchingTwoBordersIsReportedOneIsNot) {
  cv::Mat cut(50, 80, CV_8U, cv::Scalar(0));
  cut(cv::Rect(30, 20, 10, 30)).setTo(255);  // reaches the bottom only
  EXPECT_TRUE(CheckCut(cut, cv::Mat(), false).empty());
  cut(cv::Rect(0, 45, 80, 5)).setTo(255);  // a band of ground: bottom, left and right
  std::vector<std::string> warnings = CheckCut(cut, cv::Mat(), false);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("bottom, left, right"), std::string::npos) << warnings[0];
  // On a full circle, left and right are one seam: an object across it touches one side.
  cv::Mat seam(50, 80, CV_8U, cv::Scalar(0));
  seam(cv::Rect(0, 10, 5, 10)).setTo(255);
  seam(cv::Rect(75, 10, 5, 10)).setTo(255);
  EXPECT_TRUE(CheckCut(seam, cv::Mat(), true).empty());
  EXPECT_EQ(CheckCut(seam, cv::Mat(), false).size(), 1u);
}

TEST(CutChecksTest, StrokedPartsKeepThePartsTheStrokesLieOn) {
  cv::Mat mask(40, 40, CV_8U, cv::Scalar(0)), strokes(40, 40, CV_8U, cv::Scalar(0));
  mask(cv::Rect(2, 2, 10, 10)).setTo(255);
  mask(cv::Rect(20, 20, 10, 10)).setTo(255);
  strokes.at<uint8_t>(5, 5) = 255;
  const cv::Mat parts = StrokedParts(mask, strokes);
  EXPECT_EQ(cv::countNonZero(parts), 100);
  EXPECT_EQ(parts.at<uint8_t>(25, 25), 0);
}

// A box on ground of the box's own colour, the only background stroke on the wall behind: the colour cut
// cannot tell the ground from the box and takes it, across the whole picture's width.
TEST(CutChecksTest, ACutThatLeaksIntoGroundOfTheObjectsColourIsReported) {
  const int rows = 120, cols = 160;
  Scan scan = MakeScan(rows, cols, /*with_color=*/true);
  scan.grid = UniformGrid(rows, cols, -20 * kPi / 180, 20 * kPi / 180, -25 * kPi / 180, 10 * kPi / 180);
  scan.direction = DirectionsFromGrid(scan.grid);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  cv::Mat truth(rows, cols, CV_8U, cv::Scalar(0));
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(row, col);
      double t = std::numeric_limits<double>::infinity();
      cv::Vec3b rgb(120, 140, 110);  // box and ground alike
      bool box = false;
      if (d[2] < 0) t = -1.5 / d[2];  // ground z = -1.5
      const double tb = 8.0 / d[1];   // box face y = 8
      if (std::abs(tb * d[0]) <= 0.6 && tb * d[2] >= -1.5 && tb * d[2] <= -0.2 && tb < t) t = tb, box = true;
      const double tw = 20.0 / d[1];  // wall y = 20
      if (tw * d[2] >= -1.5 && tw * d[2] <= 3.0 && tw < t) t = tw, rgb = cv::Vec3b(170, 80, 60);
      if (!std::isfinite(t)) continue;
      const double g = noise(rng);
      rgb = cv::Vec3b(cv::saturate_cast<uint8_t>(rgb[0] + 4 * g), cv::saturate_cast<uint8_t>(rgb[1] + 4 * g),
                      rgb[2]);
      const double range = t + 0.003 * noise(rng);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.range.at<float>(row, col) = static_cast<float>(range);
      scan.point.at<cv::Vec3f>(row, col) = d * static_cast<float>(range);
      scan.color.at<cv::Vec3b>(row, col) = rgb;
      if (box) truth.at<uint8_t>(row, col) = 255;
    }
  }
  cv::Mat strokes(rows, cols, CV_8U, cv::Scalar(kStrokeNone));
  const cv::Rect box = cv::boundingRect(truth);
  const cv::Point centre(box.x + box.width / 2, box.y + box.height / 2);
  cv::line(strokes, centre - cv::Point(3, 0), centre + cv::Point(3, 0), cv::Scalar(kStrokeObject), 2);
  cv::line(strokes, cv::Point(10, 30), cv::Point(40, 30), cv::Scalar(kStrokeBackground), 2);  // the wall
  SegmentOptions kept;
  kept.contain_leaks = false;  // the cut as the colour cut left it
  const SegmentResult result = SegmentObject(scan, strokes, kept);
  ASSERT_GT(result.object_cells, 3 * cv::countNonZero(truth)) << "the constructed cut did not leak";
  ASSERT_EQ(result.warnings.size(), 2u);
  EXPECT_NE(result.warnings[0].find("times that part"), std::string::npos) << result.warnings[0];
  EXPECT_NE(result.warnings[1].find("borders"), std::string::npos) << result.warnings[1];
  // By default (SegmentOptions::contain_leaks) the leak is contained: the part the strokes lie on is the cut,
  // and the one warning says so.
  const SegmentResult contained = SegmentObject(scan, strokes, SegmentOptions());
  const MaskScores scores = ScoreMask(contained.mask, truth, scan.valid);
  EXPECT_GT(scores.iou, 0.9) << "precision " << scores.precision << " recall " << scores.recall;
  ASSERT_EQ(contained.warnings.size(), 1u);
  EXPECT_NE(contained.warnings[0].find("leaked"), std::string::npos) << contained.warnings[0];
}

// The evaluation scenes' cuts are right (IoU 0.997 over three stroke seeds): none of them is reported. The
// largest growth past the strokes' part is mailbox_lawn's (seed 7920, the box on a post stroked on the post:
// 2.05 times).
TEST(CutChecksTest, TheEvaluationScenesGiveNoWarnings) {
  const char* scenes[] = {"bench_paving",    "car_gravel",      "electric_box_grass", "electric_box_wall",
                          "hatchback_grass", "mailbox_gravel",  "mailbox_lawn",       "sign_on_post",
                          "table_mug",       "trash_can_grass", "trash_can_gravel",   "two_people",
                          "van_facade"};
  for (const char* name : scenes) {
    const Scan scan =
        SynthesizeScan(LoadScene(std::string(LIDARSHOP_SOURCE_DIR "/data/segment_eval/") + name + ".json"));
    const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
    for (uint64_t seed : {7920u, 7921u, 7922u}) {
      const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, seed);
      const SegmentResult result = SegmentObject(scan, strokes, SegmentOptions());
      std::printf("%-20s seed %llu: cut %lld cells\n", name, static_cast<unsigned long long>(seed),
                  static_cast<long long>(result.object_cells));
      EXPECT_TRUE(result.warnings.empty()) << name << " seed " << seed << ": " << result.warnings.front();
    }
  }
}

}  // namespace
}  // namespace lidarshop
