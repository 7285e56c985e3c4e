#include "lidarshop/poisson/poisson.h"

#include <cmath>
#include <random>

#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/operators.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// A smooth image plus noise, H x W x channels, CV_64F.
cv::Mat RandomImage(int rows, int cols, int channels, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-0.5, 0.5);
  cv::Mat image(rows, cols, CV_64FC(channels));
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.ptr<double>(y)[x * channels + c] =
            100.0 * std::sin(0.05 * x + c) * std::cos(0.03 * y) + 10.0 * noise(rng) + 50.0 * c;
      }
    }
  }
  return image;
}

double MaxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a.reshape(1), b.reshape(1), diff);
  double max_value = 0.0;
  cv::minMaxLoc(diff, nullptr, &max_value);
  return max_value;
}

// Masks exercising the special cases of a masked domain: a hole touching two image borders, several
// disconnected holes, isolated pixels, a thin one-pixel line.
cv::Mat AwkwardMask(int rows, int cols) {
  cv::Mat mask = cv::Mat::zeros(rows, cols, CV_8U);
  cv::rectangle(mask, cv::Rect(0, 0, cols / 3, rows / 4), 255, cv::FILLED);  // top-left corner
  cv::circle(mask, cv::Point(cols / 2, rows / 2), std::min(rows, cols) / 6, 255,
             cv::FILLED);                                                           // interior disc
  cv::rectangle(mask, cv::Rect(cols - 7, rows / 2, 7, rows / 2), 255, cv::FILLED);  // right border strip
  cv::line(mask, cv::Point(5, rows - 10), cv::Point(cols / 2, rows - 3), 255, 1);   // thin line
  for (int i = 0; i < 20; ++i) mask.at<uint8_t>(3 + (i * 37) % (rows - 6), 3 + (i * 53) % (cols - 6)) = 255;
  mask.at<uint8_t>(rows - 1, 0) = 255;  // isolated corner pixel
  return mask;
}

PoissonOptions Direct() {
  PoissonOptions options;
  options.solver = PoissonSolverKind::kDirect;
  return options;
}
PoissonOptions Multigrid(double tolerance = 1e-10, int coarsest = 64) {
  PoissonOptions options;
  options.solver = PoissonSolverKind::kMultigrid;
  options.tolerance = tolerance;
  options.coarsest_max_unknowns = coarsest;
  return options;
}

TEST(PoissonOperatorsTest, DivergenceOfGradientIsTheFivePointLaplacian) {
  const cv::Mat image = RandomImage(23, 31, 2, 1);
  const ImageGradient gradient = ForwardGradient(image);
  const cv::Mat laplacian = BackwardDivergence(gradient.gx, gradient.gy);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < 2; ++c) {
        auto at = [&](int yy, int xx) { return image.ptr<double>(yy)[xx * 2 + c]; };
        double expected = 0.0;
        if (x > 0) expected += at(y, x - 1) - at(y, x);
        if (x + 1 < image.cols) expected += at(y, x + 1) - at(y, x);
        if (y > 0) expected += at(y - 1, x) - at(y, x);
        if (y + 1 < image.rows) expected += at(y + 1, x) - at(y, x);
        EXPECT_NEAR(laplacian.ptr<double>(y)[x * 2 + c], expected, 1e-11) << y << "," << x;
      }
    }
  }
  // The last column of gx and the last row of gy are the zero flux leaving the image.
  EXPECT_EQ(cv::countNonZero(gradient.gx.col(image.cols - 1).reshape(1)), 0);
  EXPECT_EQ(cv::countNonZero(gradient.gy.row(image.rows - 1).reshape(1)), 0);
  EXPECT_DOUBLE_EQ(gradient.gx.ptr<double>(4)[2 * 7 + 1],
                   image.ptr<double>(4)[2 * 8 + 1] - image.ptr<double>(4)[2 * 7 + 1]);
  // Whatever the input holds on the edges leaving the image, the divergence ignores it.
  cv::Mat gx = gradient.gx.clone();
  gx.col(image.cols - 1).setTo(cv::Scalar::all(1000.0));
  EXPECT_EQ(MaxAbsDiff(BackwardDivergence(gx, gradient.gy), laplacian), 0.0);
  EXPECT_EQ(MaxAbsDiff(Laplacian5(image), laplacian), 0.0);
  EXPECT_THROW(BackwardDivergence(gradient.gx, gradient.gy.colRange(0, 5)), InputError);
}

TEST(PoissonOperatorsTest, FloatInputStaysFloat) {
  cv::Mat image(5, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  image.at<cv::Vec3b>(2, 3) = cv::Vec3b(40, 50, 60);
  const ImageGradient gradient = ForwardGradient(image);
  EXPECT_EQ(gradient.gx.type(), CV_32FC3);
  EXPECT_FLOAT_EQ(gradient.gx.at<cv::Vec3f>(2, 2)[1], 30.0f);
  EXPECT_FLOAT_EQ(gradient.gy.at<cv::Vec3f>(2, 3)[2], -30.0f);
}

// Reconstructing an image from its own gradients must return it, with the direct and the multigrid solver.
class PoissonSolverTest : public ::testing::TestWithParam<PoissonSolverKind> {
 protected:
  PoissonOptions Options() const { return GetParam() == PoissonSolverKind::kDirect ? Direct() : Multigrid(); }
};

TEST_P(PoissonSolverTest, ReconstructsAnImageFromItsOwnGradients) {
  const cv::Mat image = RandomImage(96, 128, 3, 2);
  const cv::Mat mask = AwkwardMask(96, 128);
  const PoissonSystem system = PreparePoisson(mask, Options());
  EXPECT_EQ(system.Solver(), GetParam());
  EXPECT_EQ(system.NumUnknowns(), cv::countNonZero(mask));
  cv::Mat boundary = image.clone();
  boundary.setTo(cv::Scalar::all(-777.0), mask);  // values inside Ω must not matter
  const ImageGradient gradient = ForwardGradient(image);
  const PoissonResult result = ReconstructFromGradients(system, boundary, gradient.gx, gradient.gy);
  EXPECT_EQ(result.image.type(), CV_64FC3);
  EXPECT_EQ(result.channels, 3);
  EXPECT_LT(result.relative_residual, 1e-10);
  EXPECT_LT(MaxAbsDiff(result.image, image), 1e-7) << result.Summary();
}

TEST_P(PoissonSolverTest, LaplaceFillReproducesHarmonicRamps) {
  // A linear ramp is discrete-harmonic inside the image; at the left/top border the Neumann condition holds
  // for a ramp along the other axis. So I = 3 y + 7 is reproduced in a hole touching the left border, and
  // I = 2 x − y everywhere in a hole away from the border.
  const int rows = 64, cols = 80;
  cv::Mat ramp_y(rows, cols, CV_64F), ramp_xy(rows, cols, CV_64F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      ramp_y.at<double>(y, x) = 3.0 * y + 7.0;
      ramp_xy.at<double>(y, x) = 2.0 * x - y;
    }
  }
  cv::Mat border_hole = cv::Mat::zeros(rows, cols, CV_8U);
  cv::rectangle(border_hole, cv::Rect(0, 10, 30, 40), 255, cv::FILLED);
  cv::Mat boundary = ramp_y.clone();
  boundary.setTo(0.0, border_hole);
  PoissonResult result = FillLaplace(PreparePoisson(border_hole, Options()), boundary);
  EXPECT_LT(MaxAbsDiff(result.image, ramp_y), 1e-7);

  cv::Mat inner_hole = cv::Mat::zeros(rows, cols, CV_8U);
  cv::circle(inner_hole, cv::Point(40, 30), 20, 255, cv::FILLED);
  boundary = ramp_xy.clone();
  boundary.setTo(0.0, inner_hole);
  result = FillLaplace(PreparePoisson(inner_hole, Options()), boundary);
  EXPECT_LT(MaxAbsDiff(result.image, ramp_xy), 1e-7);
}

TEST_P(PoissonSolverTest, NonFiniteValuesBesideTheHoleAreRefusedNotSpread) {
  // One NaN pixel next to the hole used to fill the whole hole with NaN; NaN inside the hole or
  // far from it is not read and must not matter.
  const int rows = 40, cols = 50;
  cv::Mat image(rows, cols, CV_32F, cv::Scalar(5.0f));
  cv::Mat hole = cv::Mat::zeros(rows, cols, CV_8U);
  cv::rectangle(hole, cv::Rect(20, 15, 10, 10), 255, cv::FILLED);
  const PoissonSystem system = PreparePoisson(hole, Options());
  image.at<float>(20, 25) = std::numeric_limits<float>::quiet_NaN();  // inside: an unknown
  image.at<float>(2, 2) = std::numeric_limits<float>::infinity();     // far away: not read
  const PoissonResult filled = FillLaplace(system, image);
  EXPECT_EQ(cv::countNonZero(filled.image(cv::Rect(20, 15, 10, 10)) != 5.0f), 0);
  image.at<float>(14, 22) = std::numeric_limits<float>::quiet_NaN();  // the row above the hole
  try {
    FillLaplace(system, image);
    ADD_FAILURE() << "a NaN beside the hole was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), testing::HasSubstr("pixel (x 22, y 14)"));
  }
}

TEST_P(PoissonSolverTest, SatisfiesTheDiscreteEquationOnAwkwardMasks) {
  const cv::Mat image = RandomImage(70, 90, 1, 3);
  const cv::Mat mask = AwkwardMask(70, 90);
  const cv::Mat guidance = RandomImage(70, 90, 1, 4);  // any field, not a gradient of anything in the hole
  const cv::Mat divergence = Laplacian5(guidance) * 0.1;
  const PoissonResult result = SolvePoisson(PreparePoisson(mask, Options()), image, divergence);
  const cv::Mat laplacian = Laplacian5(result.image);
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uint8_t>(y, x)) {
        ASSERT_NEAR(laplacian.at<double>(y, x), divergence.at<double>(y, x), 1e-7) << y << "," << x;
      } else {
        ASSERT_EQ(result.image.at<double>(y, x), image.at<double>(y, x));  // known pixels untouched
      }
    }
  }
}

TEST_P(PoissonSolverTest, SolvesEachChannelIndependently) {
  const cv::Mat image = RandomImage(40, 50, 3, 5);
  cv::Mat mask = cv::Mat::zeros(40, 50, CV_8U);
  cv::rectangle(mask, cv::Rect(10, 5, 30, 30), 255, cv::FILLED);
  const PoissonSystem system = PreparePoisson(mask, Options());
  const PoissonResult all = FillLaplace(system, image);
  std::vector<cv::Mat> planes;
  cv::split(image, planes);
  for (int c = 0; c < 3; ++c) {
    const PoissonResult one = FillLaplace(system, planes[c]);
    std::vector<cv::Mat> solved;
    cv::split(all.image, solved);
    EXPECT_LT(MaxAbsDiff(one.image, solved[c]), 1e-8);
  }
}

INSTANTIATE_TEST_SUITE_P(Solvers, PoissonSolverTest,
                         ::testing::Values(PoissonSolverKind::kDirect, PoissonSolverKind::kMultigrid),
                         [](const auto& info) { return std::string(ToString(info.param)); });

TEST(PoissonTest, MultigridAgreesWithCholmodAndEigenOnALargeHole) {
  const cv::Mat image = RandomImage(300, 400, 1, 6);
  cv::Mat mask = cv::Mat::zeros(300, 400, CV_8U);
  cv::ellipse(mask, cv::Point(200, 150), cv::Size(170, 120), 15.0, 0, 360, 255, cv::FILLED);
  cv::rectangle(mask, cv::Rect(0, 0, 400, 20), 255, cv::FILLED);  // touches the top border
  PoissonOptions ldlt = Direct();
  ldlt.direct_backend = PoissonDirectBackend::kEigenLdlt;
  const PoissonResult cholmod = FillLaplace(PreparePoisson(mask, Direct()), image);
  const PoissonResult eigen = FillLaplace(PreparePoisson(mask, ldlt), image);
  const PoissonResult multigrid = FillLaplace(PreparePoisson(mask, Multigrid(1e-8, 4000)), image);
  EXPECT_LT(cholmod.relative_residual, 1e-12);
  EXPECT_LT(MaxAbsDiff(cholmod.image, eigen.image), 1e-8);
  EXPECT_LT(multigrid.relative_residual, 1e-8);
  EXPECT_LT(MaxAbsDiff(cholmod.image, multigrid.image), 1e-4);
  EXPECT_GT(multigrid.iterations, 0);
  EXPECT_LT(multigrid.iterations, 40) << multigrid.Summary();  // a working preconditioner, not plain CG
}

TEST(PoissonTest, MultigridConvergesOnLidarLikeMasks) {
  // Masks a scan produces: random dropouts, missing scan lines (thin stripes that vanish on coarse levels),
  // and a large hole with a ragged boundary touching the image border.
  const int rows = 240, cols = 320;
  const cv::Mat image = RandomImage(rows, cols, 1, 12);
  std::mt19937 rng(13);
  cv::Mat dropouts(rows, cols, CV_8U), stripes = cv::Mat::zeros(rows, cols, CV_8U), ragged;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) dropouts.at<uint8_t>(y, x) = rng() % 100 < 45 ? 255 : 0;
    if (y % 3 == 1) stripes.row(y).setTo(255);
  }
  cv::Mat noise(rows, cols, CV_32F);
  cv::randu(noise, 0.0f, 1.0f);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 6.0);
  cv::Mat distance(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) distance.at<float>(y, x) = std::hypot(y - 100.0f, x - 20.0f) / 200.0f;
  }
  ragged = (distance + 4.0f * (noise - 0.5f)) < 0.8f;
  for (const cv::Mat& mask : {dropouts, stripes, ragged}) {
    const PoissonResult direct = FillLaplace(PreparePoisson(mask, Direct()), image);
    const PoissonResult multigrid = FillLaplace(PreparePoisson(mask, Multigrid(1e-8, 200)), image);
    EXPECT_LT(multigrid.relative_residual, 1e-8);
    EXPECT_LE(multigrid.iterations, 25) << multigrid.Summary() << " unknowns " << cv::countNonZero(mask);
    EXPECT_LT(MaxAbsDiff(direct.image, multigrid.image), 1e-4);
  }
}

TEST(PoissonTest, MultigridIsIndependentOfTheThreadCount) {
  const cv::Mat image = RandomImage(200, 200, 1, 7);
  cv::Mat mask = cv::Mat::zeros(200, 200, CV_8U);
  cv::circle(mask, cv::Point(90, 110), 80, 255, cv::FILLED);
  const PoissonSystem system = PreparePoisson(mask, Multigrid(1e-9, 100));
  const PoissonResult parallel = FillLaplace(system, image);
  PoissonResult serial;
  {
    ThreadLimit limit(1);
    serial = FillLaplace(system, image);
  }
  EXPECT_EQ(MaxAbsDiff(parallel.image, serial.image), 0.0);
  EXPECT_EQ(parallel.iterations, serial.iterations);
}

TEST(PoissonTest, SeamlessCloneOfAShiftedBrighterCopyReturnsTheTarget) {
  // The source is the target shifted by the offset and brightened by a constant: its gradients are the
  // target's, so cloning with the target's own boundary must reproduce the target exactly.
  const cv::Mat target = RandomImage(60, 80, 3, 8);
  const cv::Point offset(17, 9);
  const cv::Mat source = target(cv::Rect(offset.x, offset.y, 40, 30)).clone() + cv::Scalar::all(25.0);
  cv::Mat source_mask = cv::Mat::zeros(source.size(), CV_8U);
  cv::ellipse(source_mask, cv::Point(20, 15), cv::Size(15, 10), 0.0, 0, 360, 255, cv::FILLED);
  source_mask.row(0).setTo(
      255);  // touches the source border: edges leaving the source carry no guidance there
  cv::Mat source_inner = source_mask.clone();
  source_inner.row(0).setTo(0);
  const PoissonResult result = SeamlessClone(source, source_inner, target, offset, Direct());
  EXPECT_LT(MaxAbsDiff(result.image, target), 1e-8);

  const cv::Mat placed_mask = CloneMaskInTarget(source_mask, target.size(), offset);
  EXPECT_EQ(cv::countNonZero(placed_mask), cv::countNonZero(source_mask));
  EXPECT_EQ(placed_mask.at<uint8_t>(offset.y, offset.x), 255);
  EXPECT_THROW(SeamlessClone(source, source_mask, target, cv::Point(60, 9), Direct()), InputError);
}

TEST(PoissonTest, SeamlessCloneOnItsWindowEqualsTheWholeTargetSolve) {
  const cv::Mat target = RandomImage(50, 70, 2, 10);
  const cv::Mat source = RandomImage(30, 40, 2, 11);
  cv::Mat source_mask = cv::Mat::zeros(source.size(), CV_8U);
  cv::circle(source_mask, cv::Point(15, 12), 9, 255, cv::FILLED);
  source_mask.col(0).setTo(255);  // touches the source border
  for (const cv::Point offset : {cv::Point(5, 7), cv::Point(30, 20), cv::Point(0, 0)}) {
    const PoissonResult windowed = SeamlessClone(source, source_mask, target, offset, Direct());
    const cv::Mat mask = CloneMaskInTarget(source_mask, target.size(), offset);
    const PoissonResult whole = SolvePoisson(PreparePoisson(mask, Direct()), target,
                                             CloneDivergence(source, source_mask, target.size(), offset));
    EXPECT_LT(MaxAbsDiff(windowed.image, whole.image), 1e-9) << offset;
    cv::Mat outside_diff;
    cv::absdiff(windowed.image, target, outside_diff);
    outside_diff.setTo(0.0, mask);
    EXPECT_EQ(cv::norm(outside_diff, cv::NORM_INF), 0.0);  // untouched outside the region
  }
}

TEST(PoissonTest, RejectsBadInput) {
  const cv::Mat image = RandomImage(10, 12, 1, 9);
  EXPECT_THROW(PreparePoisson(cv::Mat()), InputError);
  EXPECT_THROW(PreparePoisson(cv::Mat(10, 12, CV_8U, cv::Scalar(255))), InputError);  // nothing known
  EXPECT_THROW(PreparePoisson(cv::Mat(10, 12, CV_32F, cv::Scalar(1))), InputError);
  cv::Mat mask = cv::Mat::zeros(10, 12, CV_8U);
  mask.at<uint8_t>(4, 4) = 1;
  const PoissonSystem system = PreparePoisson(mask);
  EXPECT_EQ(system.Solver(), PoissonSolverKind::kDirect);  // auto picks direct for tiny systems
  EXPECT_THROW(FillLaplace(system, RandomImage(11, 12, 1, 9)), InputError);
  EXPECT_THROW(SolvePoisson(system, image, RandomImage(10, 12, 2, 9)), InputError);
  PoissonOptions options;
  options.tolerance = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = {};
  options.smoothing_sweeps = 0;
  EXPECT_THROW(PreparePoisson(mask, options), OptionsError);
  EXPECT_THROW(PoissonSystem().NumUnknowns(), std::logic_error);
  // An empty mask is fine: the boundary comes back unchanged.
  const PoissonResult copy = FillLaplace(PreparePoisson(cv::Mat::zeros(10, 12, CV_8U)), image);
  EXPECT_EQ(MaxAbsDiff(copy.image, image), 0.0);
  // The input is not modified and an isolated unknown pixel is the mean of its neighbours.
  const cv::Mat before = image.clone();
  const PoissonResult one = FillLaplace(system, image);
  EXPECT_EQ(MaxAbsDiff(image, before), 0.0);
  const double mean =
      (image.at<double>(3, 4) + image.at<double>(5, 4) + image.at<double>(4, 3) + image.at<double>(4, 5)) /
      4.0;
  EXPECT_NEAR(one.image.at<double>(4, 4), mean, 1e-12);
}

TEST(PoissonTest, FillsTheF16MaskWithBothSolvers) {
  const std::string folder = LIDARSHOP_SHARED_DATA_DIR "/images/f16/";
  const cv::Mat f16 = cv::imread(folder + "f16.png", cv::IMREAD_COLOR);
  const cv::Mat mask = cv::imread(folder + "f16_mask.png", cv::IMREAD_GRAYSCALE);
  if (f16.empty() || mask.empty()) GTEST_SKIP() << "shared data not found in " << folder;
  cv::Mat image;
  f16.convertTo(image, CV_32FC3);
  const PoissonResult direct = FillLaplace(PreparePoisson(mask, Direct()), image);
  const PoissonResult multigrid = FillLaplace(PreparePoisson(mask, Multigrid(1e-6, 2000)), image);
  EXPECT_EQ(direct.image.type(), CV_32FC3);
  EXPECT_LT(multigrid.relative_residual, 1e-6);
  EXPECT_LT(MaxAbsDiff(direct.image, multigrid.image), 0.05);  // grey levels 0–255
  // A harmonic fill obeys the maximum principle: inside the hole it stays within the image's range.
  double low = 0.0, high = 0.0;
  cv::minMaxLoc(direct.image.reshape(1), &low, &high);
  EXPECT_GE(low, -1e-3);
  EXPECT_LE(high, 255.0 + 1e-3);
}

}  // namespace
}  // namespace lidarshop
