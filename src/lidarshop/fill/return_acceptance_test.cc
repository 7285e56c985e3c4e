#include "lidarshop/fill/return_acceptance.h"

#include <gtest/gtest.h>

namespace lidarshop::fill_internal {
namespace {

// 20 x 20 cells, two channels (a value and "has a return"): rows 0..4 without a return (sky), the rest with one.
// The hole is rows 10..14, cols 10..14; targets on its top rim see returns only in their known part.
struct SkyAndWall {
  cv::Mat image = cv::Mat(20, 20, CV_32FC2, cv::Scalar(100, 255));
  cv::Mat hole = cv::Mat::zeros(20, 20, CV_8U);
  SkyAndWall() {
    image.rowRange(0, 5).setTo(cv::Scalar(0, 0));
    hole(cv::Rect(10, 10, 5, 5)).setTo(255);
  }
};

TEST(ReturnConsistentAcceptance, RefusesSkyBroughtIntoAPatchThatOnlyReturned) {
  const SkyAndWall scene;
  InpaintCanvas canvas(scene.image, scene.hole, 2);
  ReturnConsistentAcceptance acceptance(nullptr, 1);
  acceptance.Initialize(canvas);
  const Pixel target{10, 12};  // known rows 8..9, hole rows 10..12
  // Source rows 1..5: the copied rows 3..5 hold sky.
  const AcceptanceVerdict sky = acceptance.Judge(canvas, target, {{3, 5}, 0.0f});
  EXPECT_FALSE(sky.accepted);
  EXPECT_TRUE(sky.hard);
  EXPECT_EQ(sky.test, "returns");
  // Source rows 6..10 (the copied rows 8..10 return): accepted.
  EXPECT_TRUE(acceptance.Judge(canvas, target, {{8, 5}, 0.0f}).accepted);
}

TEST(ReturnConsistentAcceptance, AllowsSkyWhereTheKnownPartShowsSomeAndDefersToTheInnerTests) {
  SkyAndWall scene;
  scene.image.at<cv::Vec2f>(8, 11) =
      cv::Vec2f(0, 0);  // one known cell of the target's patch without a return
  InpaintCanvas canvas(scene.image, scene.hole, 2);
  ReturnConsistentAcceptance acceptance(nullptr, 1);
  acceptance.Initialize(canvas);
  EXPECT_TRUE(acceptance.Judge(canvas, {10, 12}, {{3, 5}, 0.0f}).accepted);

  // Wrapped tests still decide what the rule lets through.
  class RejectAll : public PatchAcceptance {
   public:
    bool Accept(const InpaintCanvas&, Pixel, const SourceCandidate&) const override { return false; }
  };
  ReturnConsistentAcceptance wrapped(std::make_unique<RejectAll>(), 1);
  wrapped.Initialize(canvas);
  const AcceptanceVerdict verdict = wrapped.Judge(canvas, {10, 12}, {{8, 5}, 0.0f});
  EXPECT_FALSE(verdict.accepted);
  EXPECT_FALSE(verdict.hard);
}

}  // namespace
}  // namespace lidarshop::fill_internal
