#include <gtest/gtest.h>

#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(PoissonOptionsInfo, ExactRoundTrip) { ExpectExactRoundTrip<PoissonOptions>(); }

// The result's JSON keys in the order `lidarshop poisson --json` has always written them.
TEST(PoissonOptionsInfo, ResultKeys) {
  ExpectExactRoundTrip<PoissonResult>();
  EXPECT_EQ(InfoOf<PoissonResult>().Keys(),
            (std::vector<std::string>{"operation", "unknowns", "solver", "channels", "iterations",
                                      "relative_residual", "seconds"}));
  PoissonResult result;
  result.operation = PoissonOperation::kReconstruct;
  result.unknowns = 12;
  result.channels = 3;
  result.relative_residual = 0.25;
  EXPECT_EQ(ToJson(result).dump(),
            R"({"operation":"reconstruct","unknowns":12,"solver":"direct","channels":3,"iterations":0,)"
            R"("relative_residual":0.25,"seconds":0.0})");
}

// Each entry point says what it solved and for how many pixels.
TEST(PoissonOptionsInfo, ResultSaysTheOperation) {
  cv::Mat image(8, 9, CV_32FC1, cv::Scalar(2.0f));
  cv::Mat mask = cv::Mat::zeros(8, 9, CV_8U);
  mask(cv::Rect(3, 2, 3, 4)).setTo(255);
  const PoissonSystem system = PreparePoisson(mask, PoissonOptions{});
  const PoissonResult fill = FillLaplace(system, image);
  EXPECT_EQ(fill.operation, PoissonOperation::kFill);
  EXPECT_EQ(fill.unknowns, 12);
  const cv::Mat zero = cv::Mat::zeros(8, 9, CV_32FC1);
  EXPECT_EQ(ReconstructFromGradients(system, image, zero, zero).operation, PoissonOperation::kReconstruct);
  EXPECT_EQ(SolvePoisson(system, image).operation, PoissonOperation::kSolve);
  const PoissonResult clone = SeamlessClone(image, mask, image, cv::Point(1, 1));
  EXPECT_EQ(clone.operation, PoissonOperation::kClone);
  EXPECT_EQ(clone.unknowns, 12);
}

TEST(PoissonOptionsInfo, Errors) {
  ExpectRejected<PoissonOptions>({{"tolerance", 1.0}}, "tolerance", "out of range (0, 1)");
  ExpectRejected<PoissonOptions>({{"solver", "cholmod"}}, "solver", "auto|direct|multigrid");
  EXPECT_EQ(ToString(PoissonDirectBackend::kEigenLdlt), "eigen-ldlt");
}

}  // namespace lidarshop
