#include "lidarshop/recolor/seam_blend.h"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/operators.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Two photos meet at column 20 of a 30 x 40 grid; photo 2's side is 30 units brighter (an exposure step) on a
// ramp the guidance describes. Blended: no step at the seam, the ramp's slope everywhere, the cells outside the
// band unchanged; a cell without colour stays 0 and carries no flux.
TEST(BlendSeams, RemovesAStepAndKeepsTheGradient) {
  const int rows = 30, cols = 40, band = 5;
  cv::Mat colour(rows, cols, CV_32FC3), photo(rows, cols, CV_16U),
      gx(rows, cols, CV_32FC3, cv::Scalar::all(0)), gy = gx.clone();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double ramp = 2.0 * c;
      colour.at<cv::Vec3f>(r, c) = cv::Vec3f::all(ramp + (c >= 20 ? 30 : 0));
      photo.at<uint16_t>(r, c) = c >= 20 ? 2 : 1;
      if (c + 1 < cols) gx.at<cv::Vec3f>(r, c) = cv::Vec3f::all(2.0);  // the true slope, also across the seam
    }
  }
  photo.at<uint16_t>(0, 0) = 0;  // no colour: 0, and no guidance from it
  colour.at<cv::Vec3f>(0, 0) = cv::Vec3f();
  gx.at<cv::Vec3f>(0, 0) = cv::Vec3f();
  const SeamBlendResult result = BlendSeams(colour, photo, gx, gy, band);
  EXPECT_EQ(result.seam_edges, rows);
  EXPECT_EQ(result.unknowns, rows * 2 * (band + 1));  // columns 14..25 (band cells each side of 19|20)
  for (int r = 0; r < rows; ++r) {
    const double step = result.colour.at<cv::Vec3f>(r, 20)[1] - result.colour.at<cv::Vec3f>(r, 19)[1];
    EXPECT_NEAR(step, 2.0 + 30.0 / (2 * band + 3), 1e-4) << r;  // the 30-unit step spread over the band
    EXPECT_EQ(result.colour.at<cv::Vec3f>(r, 5)[0], colour.at<cv::Vec3f>(r, 5)[0]);
    EXPECT_EQ(result.colour.at<cv::Vec3f>(r, 30)[2], colour.at<cv::Vec3f>(r, 30)[2]);
  }
  // No seam: unchanged.
  const cv::Mat one = cv::Mat(rows, cols, CV_16U, cv::Scalar(1));
  const SeamBlendResult none = BlendSeams(colour, one, gx, gy, band);
  EXPECT_EQ(none.seam_edges, 0);
  EXPECT_EQ(cv::norm(none.colour, colour, cv::NORM_INF), 0);
  EXPECT_THROW(BlendSeams(colour, photo, gx, gy, 0), InputError);
  cv::Mat leaking = gx.clone();
  leaking.at<cv::Vec3f>(0, 0) = cv::Vec3f::all(1);  // flux out of a cell without colour
  EXPECT_THROW(BlendSeams(colour, photo, leaking, gy, band), InputError);
  EXPECT_THROW(BlendSeams(colour, photo, gx(cv::Rect(0, 0, 10, 10)), gy, band), InputError);
}

// Guidance out of a coloured cell, or a colour where no photo coloured the cell, is refused naming the first such
// cell in row-major order (the rows are checked in parallel).
TEST(BlendSeams, RefusesFluxOutOfTheColouredCellsNamingTheFirstCell) {
  const int rows = 200, cols = 50;
  cv::Mat colour(rows, cols, CV_32FC3, cv::Scalar::all(10)), photo(rows, cols, CV_16U, cv::Scalar(1)),
      gx(rows, cols, CV_32FC3, cv::Scalar::all(0)), gy = gx.clone();
  photo.at<uint16_t>(150, 7) = 0, colour.at<cv::Vec3f>(150, 7) = cv::Vec3f();
  photo.at<uint16_t>(90, 3) = 0, colour.at<cv::Vec3f>(90, 3) = cv::Vec3f();
  gx.at<cv::Vec3f>(150, 6) = cv::Vec3f(1, 0, 0);  // into the uncoloured cell (150, 7)
  const auto message = [&] {
    try {
      BlendSeams(colour, photo, gx, gy, 2);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message().find("cell (150, 6)"), std::string::npos) << message();
  colour.at<cv::Vec3f>(90, 3) = cv::Vec3f(5, 5, 5);  // an earlier row: that one is named
  EXPECT_NE(message().find("cell (90, 3)"), std::string::npos) << message();
  EXPECT_NE(message().find("colour"), std::string::npos) << message();
}

// The band's equations assembled from the band alone are the Poisson engine's for the band mask (no-data where
// no photo coloured a cell), so the solution is the engine's to the bit: on random photo regions with holes, an
// island wholly within the band (anchored) and random colours and guidance.
TEST(BlendSeams, EqualsThePoissonEngineOnTheBandMaskBitForBit) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> value(0, 255), step(-20, 20);
  const int rows = 90, cols = 120, band = 3;
  cv::Mat photo(rows, cols, CV_16U), colour(rows, cols, CV_32FC3, cv::Scalar::all(0));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      photo.at<uint16_t>(r, c) = static_cast<uint16_t>(1 + (c * 3 + r) / 70 + (r > 2 * c - 40 ? 3 : 0));
      if (random() % 17 == 0) photo.at<uint16_t>(r, c) = 0;  // holes
    }
  }
  cv::rectangle(photo, cv::Rect(90, 60, 9, 9), cv::Scalar(0), 1);  // a ring of no colour around an island
  cv::rectangle(photo, cv::Rect(91, 61, 7, 7), cv::Scalar(1), cv::FILLED);
  cv::rectangle(photo, cv::Rect(94, 61, 4, 7), cv::Scalar(2), cv::FILLED);  // with a seam: all in the band
  cv::Mat gx(rows, cols, CV_32FC3, cv::Scalar::all(0)), gy = gx.clone();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (photo.at<uint16_t>(r, c) == 0) continue;
      colour.at<cv::Vec3f>(r, c) = cv::Vec3f(value(random), value(random), value(random));
      if (c + 1 < cols && photo.at<uint16_t>(r, c + 1) != 0)
        gx.at<cv::Vec3f>(r, c) = cv::Vec3f(step(random), step(random), step(random));
      if (r + 1 < rows && photo.at<uint16_t>(r + 1, c) != 0)
        gy.at<cv::Vec3f>(r, c) = cv::Vec3f(step(random), step(random), step(random));
    }
  }
  const SeamBlendResult result = BlendSeams(colour, photo, gx, gy, band);

  // The reference: the band mask, its coloured parts without a known cell anchored at their first cell.
  const cv::Mat coloured = photo > 0;
  cv::Mat seam = cv::Mat::zeros(rows, cols, CV_8U);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const uint16_t p = photo.at<uint16_t>(r, c);
      if (p == 0) continue;
      for (const auto& [nr, nc] : {std::pair{r, c + 1}, std::pair{r + 1, c}}) {
        if (nr >= rows || nc >= cols) continue;
        const uint16_t q = photo.at<uint16_t>(nr, nc);
        if (q != 0 && q != p) seam.at<uint8_t>(r, c) = seam.at<uint8_t>(nr, nc) = 255;
      }
    }
  }
  cv::Mat mask;
  cv::dilate(seam, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * band + 1, 2 * band + 1)));
  mask &= coloured;
  cv::Mat labels;
  const int parts = cv::connectedComponents(coloured, labels, 4, CV_32S);
  std::vector<char> has_known(parts, 0);
  std::vector<cv::Point> first(parts, cv::Point(-1, -1));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int label = labels.at<int>(r, c);
      if (label == 0) continue;
      if (first[label].x < 0) first[label] = cv::Point(c, r);
      if (!mask.at<uint8_t>(r, c)) has_known[label] = 1;
    }
  }
  int anchored = 0;
  for (int label = 1; label < parts; ++label) {
    if (!has_known[label]) mask.at<uint8_t>(first[label]) = 0, ++anchored;
  }
  ASSERT_GE(anchored, 1);  // the island
  PoissonOptions options;
  options.solver = PoissonSolverKind::kDirect;
  PoissonLinks links;
  links.no_data = coloured == 0;
  const PoissonSystem system = PreparePoisson(mask, options, links);
  const cv::Mat expected = SolvePoisson(system, colour, BackwardDivergence(gx, gy)).image;
  EXPECT_EQ(result.unknowns, cv::countNonZero(mask));
  EXPECT_GT(result.unknowns, 1000);
  int differing = 0;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      for (int ch = 0; ch < 3; ++ch) {
        if (result.colour.at<cv::Vec3f>(r, c)[ch] != expected.at<cv::Vec3f>(r, c)[ch]) {
          if (++differing <= 5)
            ADD_FAILURE() << "(" << r << ", " << c << ")[" << ch
                          << "]: " << result.colour.at<cv::Vec3f>(r, c)[ch] << " vs "
                          << expected.at<cv::Vec3f>(r, c)[ch];
        }
      }
    }
  }
  EXPECT_EQ(differing, 0);
}

}  // namespace
}  // namespace lidarshop
