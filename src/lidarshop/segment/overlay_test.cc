#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"

namespace lidarshop {
namespace {

// A scan whose every cell returns, coloured `rgb`.
Scan UniformScan(int rows, int cols, cv::Vec3b rgb) {
  Scan scan = MakeScan(rows, cols, /*with_color=*/true);
  scan.valid.setTo(1);
  scan.range.setTo(5.0f);
  scan.color.setTo(cv::Scalar(rgb[0], rgb[1], rgb[2]));
  return scan;
}

double LabDistance(cv::Vec3b a, cv::Vec3b b) {
  cv::Mat two(1, 2, CV_8UC3), lab;
  two.at<cv::Vec3b>(0, 0) = a;
  two.at<cv::Vec3b>(0, 1) = b;
  two.convertTo(two, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(two, lab, cv::COLOR_RGB2Lab);
  return cv::norm(lab.at<cv::Vec3f>(0, 0) - lab.at<cv::Vec3f>(0, 1));
}

TEST(OverlayTest, TintIsYellowOnGrassAndNotOnAYellowFacade) {
  const cv::Vec3b grass(74, 112, 42), facade(230, 205, 60);
  const cv::Mat on_grass(50, 60, CV_8UC3, cv::Scalar(grass[0], grass[1], grass[2]));
  EXPECT_EQ(ContrastingOverlayColor(on_grass), cv::Vec3b(255, 220, 0));
  const cv::Mat on_facade(50, 60, CV_8UC3, cv::Scalar(facade[0], facade[1], facade[2]));
  const cv::Vec3b chosen = ContrastingOverlayColor(on_facade);
  EXPECT_NE(chosen, cv::Vec3b(255, 220, 0));
  // Far from the facade in CIELAB, farther than yellow is.
  EXPECT_GT(LabDistance(chosen, facade), 2 * LabDistance(cv::Vec3b(255, 220, 0), facade));
}

TEST(OverlayTest, RegionDecidesNotTheWholePicture) {
  cv::Mat picture(40, 40, CV_8UC3, cv::Scalar(74, 112, 42));          // grass...
  picture(cv::Rect(10, 10, 20, 20)).setTo(cv::Scalar(240, 215, 40));  // ...with a yellow object
  cv::Mat object = cv::Mat::zeros(40, 40, CV_8U);
  object(cv::Rect(10, 10, 20, 20)).setTo(255);
  EXPECT_NE(ContrastingOverlayColor(picture, object), cv::Vec3b(255, 220, 0));
}

TEST(OverlayTest, OverlayOutlineUsesTheChosenColourAndStrokesAreThick) {
  const Scan scan = UniformScan(900, 1800, cv::Vec3b(230, 205, 60));
  cv::Mat mask = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
  mask(cv::Rect(800, 300, 200, 300)).setTo(255);
  cv::Mat strokes = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
  strokes.at<uint8_t>(450, 900) = kStrokeObject;
  strokes.at<uint8_t>(100, 100) = kStrokeBackground;
  const cv::Mat overlay = SegmentOverlay(scan, mask, strokes);
  const cv::Vec3b outline = overlay.at<cv::Vec3b>(300, 900);
  EXPECT_EQ(outline, ContrastingOverlayColor(scan.color, [&] {
              cv::Mat around;
              cv::dilate(mask, around, cv::Mat(), cv::Point(-1, -1), 5);
              return around;
            }()));
  EXPECT_NE(outline, cv::Vec3b(255, 220, 0));
  // One stroke cell becomes a disc of radius OverlayStrokeRadius (4 at 1800 cells across), rimmed in black.
  const int radius = OverlayStrokeRadius(overlay.size());
  EXPECT_EQ(radius, 4);
  cv::Mat green;
  cv::inRange(overlay, cv::Scalar(0, 255, 0), cv::Scalar(0, 255, 0), green);
  EXPECT_EQ(cv::countNonZero(green),
            cv::countNonZero(cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9))));
  EXPECT_EQ(overlay.at<cv::Vec3b>(100, 100 + radius), cv::Vec3b(255, 0, 0));
  EXPECT_EQ(overlay.at<cv::Vec3b>(100, 100 + radius + 1), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace lidarshop
