// The evaluation set's claims, as a test: on data/segment_eval (one stroke seed, grabCut left to segment_eval
// for time), the two-step cut beats the depth-only, colour-only and single-step RGB+D cuts on mean IoU, and
// its step 1 is nearly background-free (mean precision >= 0.99).
#include <map>

#include <gtest/gtest.h>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/segment/segment_eval.h"

namespace lidarshop {
namespace {

TEST(SegmentEvalTest, TwoStepBeatsTheBaselinesAndStepOneIsClean) {
  const char* scenes[] = {"car_gravel",       "electric_box_grass", "electric_box_wall", "hatchback_grass",
                          "mailbox_gravel",   "mailbox_lawn",       "sign_on_post",      "trash_can_grass",
                          "trash_can_gravel", "van_facade"};
  std::map<std::string, double> iou, precision;
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
    }
    ++runs;
  }
  for (auto& [method, value] : iou) {
    value /= runs;
    precision[method] /= runs;
    std::printf("%-9s mean IoU %.3f  mean precision %.3f\n", method.c_str(), value, precision[method]);
  }
  EXPECT_GT(iou["two-step"], iou["depth"]);
  EXPECT_GT(iou["two-step"], iou["color"]);
  EXPECT_GT(iou["two-step"], iou["rgbd"]);
  EXPECT_GE(precision["step-1"], 0.99);
  EXPECT_GT(iou["two-step"], 0.85);
}

}  // namespace
}  // namespace lidarshop
