// The evaluation set's claims, as a test: on data/segment_eval (one stroke seed, grabCut left to segment_eval
// for time), the two-step cut beats the depth-only, colour-only and single-step RGB+D cuts on mean IoU, and
// its step 1 is nearly background-free (precision >= 0.98), touching neighbours included.
#include <map>

#include <gtest/gtest.h>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment_eval.h"

namespace lidarshop {
namespace {

TEST(SegmentEvalTest, UpperAndBelowStrokesLieOnTheObjectsTopAndUnderIt) {
  // An object of rows 50..149 and columns 100..199 in a 300 x 400 grid of returns.
  const cv::Mat valid(300, 400, CV_8U, cv::Scalar(255));
  cv::Mat truth(300, 400, CV_8U, cv::Scalar(0));
  truth(cv::Rect(100, 50, 100, 100)).setTo(255);
  EvalStrokeOptions options;
  options.upper_and_below = true;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const cv::Mat strokes = MakeEvalStrokes(truth, valid, seed, options);
    std::vector<cv::Point> object, background;
    cv::findNonZero(strokes == kStrokeObject, object);
    cv::findNonZero(strokes == kStrokeBackground, background);
    ASSERT_FALSE(object.empty());
    ASSERT_FALSE(background.empty());
    // The eroded object spans rows 54..145: its upper third ends at row 54 + 30; a 2-cell stroke adds a row.
    for (const cv::Point& p : object) EXPECT_LE(p.y, 54 + 30 + 1) << seed;
    for (const cv::Point& p : background) {
      EXPECT_GE(p.y, 150) << seed;
      EXPECT_GE(p.x, 100) << seed;
      EXPECT_LE(p.x, 199) << seed;
    }
  }
  // With no room under the object (it reaches the bottom row), the background stroke goes elsewhere.
  cv::Mat low(300, 400, CV_8U, cv::Scalar(0));
  low(cv::Rect(100, 200, 100, 100)).setTo(255);
  const cv::Mat strokes = MakeEvalStrokes(low, valid, 3, options);
  EXPECT_GT(cv::countNonZero(strokes == kStrokeBackground), 0);
}

TEST(SegmentEvalTest, GroundTheDepthCutTookAtTheFootIsLeftToTheColourCut) {
  // electric_box_wall: step 1 takes a fringe of the ground at the box's foot; as hard object seeds those cells
  // stayed in the final mask (IoU 0.990 over the eval's seeds), left free the colour cut drops them.
  const Scan scan = SynthesizeScan(
      LoadScene(std::string(LIDARSHOP_SOURCE_DIR "/data/segment_eval/electric_box_wall.json")));
  const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
  double gain = 0;
  for (uint64_t seed : {7920u, 7921u, 7922u}) {
    const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, seed);
    SegmentOptions options;
    const double freed = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid).iou;
    options.whole_object.free_support_seeds = false;
    const double forced = ScoreMask(SegmentObject(scan, strokes, options).mask, truth, scan.valid).iou;
    EXPECT_GE(freed, forced - 1e-9) << seed;
    gain += freed - forced;
  }
  EXPECT_GT(gain, 0.005);
}

TEST(SegmentEvalTest, TwoStepBeatsTheBaselinesAndStepOneIsClean) {
  const char* scenes[] = {"bench_paving",    "car_gravel",      "electric_box_grass", "electric_box_wall",
                          "hatchback_grass", "mailbox_gravel",  "mailbox_lawn",       "sign_on_post",
                          "table_mug",       "trash_can_grass", "trash_can_gravel",   "two_people",
                          "van_facade"};
  std::map<std::string, double> iou, precision, step1_precision;
  int runs = 0;
  for (const char* name : scenes) {
    const Scan scan =
        SynthesizeScan(LoadScene(std::string(LIDARSHOP_SOURCE_DIR "/data/segment_eval/") + name + ".json"));
    const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
    const cv::Mat strokes = MakeEvalStrokes(truth, scan.valid, 7920);
    for (const MethodScores& s :
         EvaluateMethods(scan, truth, strokes, SegmentOptions(), /*grabcut_iterations=*/0)) {
      iou[s.method] += s.scores.iou;
      precision[s.method] += s.scores.precision;
      if (s.method == "step-1") step1_precision[name] = s.scores.precision;
    }
    ++runs;
  }
  // Step 1 stops at depth edges and at the crevice where a neighbour touches the object at the same range
  // (two_people: ~0.5 before TouchingNeighbours): nearly background-free everywhere.
  for (const auto& [name, value] : step1_precision) EXPECT_GE(value, 0.98) << name;
  for (auto& [method, value] : iou) {
    value /= runs;
    precision[method] /= runs;
    std::printf("%-9s mean IoU %.3f  mean precision %.3f\n", method.c_str(), value, precision[method]);
  }
  EXPECT_GT(iou["two-step"], iou["depth"]);
  EXPECT_GT(iou["two-step"], iou["color"]);
  EXPECT_GT(iou["two-step"], iou["rgbd"]);
  // Measured 0.997 over 3 seeds: 0.943 before touching neighbours were separated (two_people 0.500 -> 0.999),
  // overhanging parts joined (mailbox_gravel 0.884 -> 0.998, mailbox_lawn 0.897 -> 0.973) and support cells
  // allowed a 60° normal tilt (0.996 -> 0.997); 0.998 with free support seeds and a 75° tilt.
  EXPECT_GT(iou["two-step"], 0.97);
}

// #15: a correct refinement stroke never lowers IoU by more than 0.01 (one stroke per scene, on the largest
// missed part or else the largest wrongly taken part).
TEST(SegmentEvalTest, ACorrectRefinementNeverLowersIoU) {
  const char* scenes[] = {"bench_paving",    "car_gravel",      "electric_box_grass", "electric_box_wall",
                          "hatchback_grass", "mailbox_gravel",  "mailbox_lawn",       "sign_on_post",
                          "table_mug",       "trash_can_grass", "trash_can_gravel",   "two_people",
                          "van_facade"};
  int refined = 0;
  for (const char* name : scenes) {
    const Scan scan =
        SynthesizeScan(LoadScene(std::string(LIDARSHOP_SOURCE_DIR "/data/segment_eval/") + name + ".json"));
    const cv::Mat truth = (scan.label == 1) & (scan.valid != 0);
    const RefinementScores r =
        EvaluateRefinement(scan, truth, MakeEvalStrokes(truth, scan.valid, 7920), SegmentOptions());
    std::printf("%-20s %-10s IoU %.3f -> %.3f\n", name, r.stroke.c_str(), r.before.iou, r.after.iou);
    EXPECT_GE(r.after.iou, r.before.iou - 0.01) << name;
    refined += r.stroke != "none";
  }
  EXPECT_GT(refined, 10);  // an exact cut gets a background stroke away from the object
}

}  // namespace
}  // namespace lidarshop
