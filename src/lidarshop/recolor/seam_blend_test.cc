#include "lidarshop/recolor/seam_blend.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lidarshop
