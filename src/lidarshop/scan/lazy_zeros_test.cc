#include "lidarshop/scan/lazy_zeros.h"

#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace lidarshop {
namespace {

int64_t ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

TEST(LazyZeros, ReadsZeroAndWritesLikeAnyMatrix) {
  cv::Mat mask = LazyZeros(300, 500, CV_8U);
  ASSERT_EQ(mask.rows, 300);
  ASSERT_EQ(mask.cols, 500);
  ASSERT_EQ(mask.type(), CV_8U);
  EXPECT_TRUE(mask.isContinuous());
  EXPECT_EQ(cv::countNonZero(mask), 0);
  mask(cv::Rect(10, 20, 30, 40)).setTo(255);
  EXPECT_EQ(cv::countNonZero(mask), 30 * 40);
  cv::Mat copy = mask.clone();
  mask.setTo(0);
  EXPECT_EQ(cv::countNonZero(copy), 30 * 40);
  const cv::Mat floats = LazyZeros(7, 9, CV_32FC3);
  EXPECT_EQ(cv::norm(floats, cv::NORM_INF), 0.0);
  EXPECT_EQ(floats.step, static_cast<size_t>(9 * 12));
}

TEST(LazyZeros, ACopyOfAMostlyZeroImageEqualsIt) {
  cv::Mat strokes = cv::Mat::zeros(200, 300, CV_8U);
  strokes(cv::Rect(20, 30, 100, 3)).setTo(1);
  strokes.at<uint8_t>(199, 299) = 2;
  strokes.at<uint8_t>(0, 0) = 2;
  const cv::Mat copy = CopyOfMostlyZero(strokes);
  EXPECT_EQ(cv::norm(copy, strokes, cv::NORM_INF), 0.0);
  EXPECT_NE(copy.data, strokes.data);
  EXPECT_EQ(cv::countNonZero(CopyOfMostlyZero(cv::Mat::zeros(5, 5, CV_8U))), 0);
  const cv::Mat box_copy = CopyOfBox(strokes, cv::Rect(0, 0, 300, 200));
  EXPECT_EQ(cv::norm(box_copy, strokes, cv::NORM_INF), 0.0);
  // Only the box is copied: a value outside it is not.
  EXPECT_EQ(cv::countNonZero(CopyOfBox(strokes, cv::Rect(20, 30, 100, 3))), 100 * 3);
  EXPECT_EQ(cv::countNonZero(CopyOfBox(strokes, cv::Rect())), 0);
}

TEST(LazyZeros, TheNonZeroBoxWithinABoxIsTheBoundingBoxOfWhatItHolds) {
  cv::Mat mask = cv::Mat::zeros(20, 30, CV_8U);
  mask(cv::Rect(4, 5, 3, 2)).setTo(255);
  mask.at<uint8_t>(15, 25) = 255;
  EXPECT_EQ(NonZeroBoxWithin(mask, cv::Rect(0, 0, 30, 20)), cv::boundingRect(mask));
  EXPECT_EQ(NonZeroBoxWithin(mask, cv::Rect(2, 3, 10, 10)), cv::Rect(4, 5, 3, 2));
  EXPECT_EQ(NonZeroBoxWithin(mask, cv::Rect(20, 10, 50, 50)), cv::Rect(25, 15, 1, 1));  // clipped to the mask
  EXPECT_TRUE(NonZeroBoxWithin(mask, cv::Rect(10, 0, 5, 5)).empty());
  EXPECT_TRUE(NonZeroBoxWithin(mask, cv::Rect()).empty());
}

// The point of it: a 1 GiB mask written in one window costs that window's pages, not the gigabyte
// (cv::Mat::zeros would make the whole of it resident).
TEST(LazyZeros, AGigabyteWrittenInAWindowStaysSmall) {
  const int64_t before = ResidentBytes();
  cv::Mat mask = LazyZeros(32768, 32768, CV_8U);
  mask(cv::Rect(1000, 1000, 2000, 100)).setTo(255);
  const int64_t grown = ResidentBytes() - before;
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(0, 0, 4096, 4096))), 2000 * 100);
  EXPECT_LT(grown, int64_t{64} << 20) << "resident memory grew by " << grown << " bytes";
  // (Reading the untouched cells reads zeros; whether that makes them resident depends on the kernel: the
  // Firecracker VMs we run on give a read fault a page of its own, so it is not asserted.)
  EXPECT_EQ(cv::countNonZero(mask), 2000 * 100);
}

}  // namespace
}  // namespace lidarshop
