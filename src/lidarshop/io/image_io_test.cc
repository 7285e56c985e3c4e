#include "lidarshop/io/image_io.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::TempFolder;

TEST(ImageIoTest, RgbOrderAtTheFileBoundary) {
  TempFolder folder;
  cv::Mat rgb(3, 4, CV_8UC3, cv::Scalar(255, 0, 0));  // pure red in lidarshop's RGB
  WriteImage(folder.File("red.png"), rgb);
  const cv::Mat bgr = cv::imread(folder.File("red.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));  // OpenCV sees red as BGR
  const cv::Mat back = ReadImage(folder.File("red.png"));
  EXPECT_EQ(back.at<cv::Vec3b>(2, 3), cv::Vec3b(255, 0, 0));
}

TEST(ImageIoTest, SixteenBitPngAndFloatExr) {
  TempFolder folder;
  cv::Mat labels(2, 3, CV_16U, cv::Scalar(65535));
  labels.at<uint16_t>(1, 2) = 4;
  WriteImage(folder.File("labels.png"), labels);
  const cv::Mat labels_back = ReadImage(folder.File("labels.png"));
  ASSERT_EQ(labels_back.type(), CV_16U);
  EXPECT_EQ(cv::norm(labels_back, labels, cv::NORM_INF), 0.0);

  cv::Mat depth(2, 3, CV_32F, cv::Scalar(12.345f));
  depth.at<float>(0, 0) = 0.001f;
  WriteImage(folder.File("depth.exr"), depth);
  const cv::Mat depth_back = ReadImage(folder.File("depth.exr"));
  ASSERT_EQ(depth_back.type(), CV_32F);
  EXPECT_EQ(cv::norm(depth_back, depth, cv::NORM_INF), 0.0);
}

TEST(ImageIoTest, FloatPngIsRefusedAndNothingIsWritten) {
  TempFolder folder;
  EXPECT_THROW(WriteImage(folder.File("depth.png"), cv::Mat(2, 2, CV_32F, cv::Scalar(1))), InputError);
  EXPECT_FALSE(std::filesystem::exists(folder.File("depth.png")));
}

TEST(ImageIoTest, DecodeImage) {
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)), png);  // BGR 1 2 3
  EXPECT_EQ(DecodeImage(png, "blob").at<cv::Vec3b>(0, 0), cv::Vec3b(3, 2, 1));
  EXPECT_THROW(DecodeImage({1, 2, 3, 4}, "blob"), InputError);
}

}  // namespace
}  // namespace lidarshop
