#include "lidarshop/io/image_io.h"

#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

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

// The header reader gives the size and channels every format lidarshop writes stores, without decoding.
TEST(ImageIoTest, HeaderOfEveryFormat) {
  TempFolder folder;
  const struct {
    const char* name;
    cv::Mat image;
    int channels, bytes_per_channel;
  } kCases[] = {{"a.png", cv::Mat(7, 5, CV_8UC3, cv::Scalar(1, 2, 3)), 3, 1},
                {"a16.png", cv::Mat(7, 5, CV_16U, cv::Scalar(9)), 1, 2},
                {"a.jpg", cv::Mat(7, 5, CV_8UC3, cv::Scalar(1, 2, 3)), 3, 1},
                {"a.tif", cv::Mat(7, 5, CV_8UC4, cv::Scalar(1, 2, 3, 4)), 4, 1},
                {"a32.tif", cv::Mat(7, 5, CV_32F, cv::Scalar(1)), 1, 4},
                {"a.exr", cv::Mat(7, 5, CV_32FC3, cv::Scalar(1, 2, 3)), 3, 4},
                {"a.bmp", cv::Mat(7, 5, CV_8UC3, cv::Scalar(1, 2, 3)), 3, 1}};
  for (const auto& c : kCases) {
    SCOPED_TRACE(c.name);
    WriteImage(folder.File(c.name), c.image);
    const std::string bytes = ReadRegularFile(folder.File(c.name));
    const ImageHeader header =
        ReadImageHeader(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), c.name);
    EXPECT_EQ(header.width, 5);
    EXPECT_EQ(header.height, 7);
    EXPECT_EQ(header.channels, c.channels);
    EXPECT_EQ(header.bytes_per_channel, c.bytes_per_channel);
    EXPECT_EQ(ReadImage(folder.File(c.name)).size(), cv::Size(5, 7));
  }
}

// A PNG whose IHDR claims 20000 x 20000 pixels is refused from its header: past the pixel limit, past the
// budget, or (a mask, strokes) not the size expected — before any decoder allocates for it.
TEST(ImageIoTest, SizeIsCheckedFromTheHeaderBeforeDecoding) {
  TempFolder folder;
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(4, 6, CV_8U, cv::Scalar(255)), png);
  const auto store_be = [](std::vector<uint8_t>* bytes, size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) (*bytes)[at + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
  };
  // The IHDR's CRC goes stale: only a decoder would notice.
  auto with_size = [&](uint32_t width, uint32_t height) {
    std::vector<uint8_t> copy = png;
    store_be(&copy, 16, width);
    store_be(&copy, 20, height);
    return copy;
  };
  const std::vector<uint8_t> huge = with_size(20000, 20000);
  try {
    DecodeImage(huge, "blob");
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("20000 x 20000 pixels: more than"), std::string::npos)
        << error.what();
  }
  // Within the pixel limit but not the budget.
  const int64_t budget = MemoryBudgetBytes();
  SetMemoryBudgetBytes(int64_t{1} << 20);
  EXPECT_THROW(DecodeImage(with_size(1000, 1000), "blob"), InputError);
  SetMemoryBudgetBytes(budget);
  // A mask of the wrong size is named as such although its pixel data would not even decode.
  const std::string mask = folder.File("mask.png");
  {
    const std::vector<uint8_t> wrong = with_size(60, 40);
    std::ofstream(mask, std::ios::binary).write(reinterpret_cast<const char*>(wrong.data()), wrong.size());
  }
  try {
    ReadMask(mask, cv::Size(6, 4), "the scan");
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("60x40 but the scan is 6x4"), std::string::npos) << error.what();
  }
  std::ofstream(mask, std::ios::binary).write(reinterpret_cast<const char*>(png.data()), png.size());
  EXPECT_EQ(cv::countNonZero(ReadMask(mask, cv::Size(6, 4), "the scan")), 24);
}

// Truncated or lying headers are InputErrors, never reads past the bytes.
TEST(ImageIoTest, TruncatedHeadersAreRefused) {
  std::vector<uint8_t> jpeg, tiff;
  cv::imencode(".jpg", cv::Mat(3, 3, CV_8UC3, cv::Scalar(1, 2, 3)), jpeg);
  cv::imencode(".tif", cv::Mat(3, 3, CV_8UC3, cv::Scalar(1, 2, 3)), tiff);
  for (const std::vector<uint8_t>* bytes : {&jpeg, &tiff}) {
    for (size_t cut : {size_t{3}, size_t{5}, size_t{9}, size_t{20}}) {
      EXPECT_THROW(ReadImageHeader(bytes->data(), cut, "cut"), InputError) << cut;
    }
  }
  // A JPEG whose data starts before any frame header.
  const std::vector<uint8_t> no_frame = {0xff, 0xd8, 0xff, 0xda, 0x00, 0x02, 0xff, 0xd9};
  EXPECT_THROW(ReadImageHeader(no_frame.data(), no_frame.size(), "sos"), InputError);
}

// libpng's own "libpng error: ..." line does not reach stderr: it is part of the one error.
TEST(ImageIoTest, DecoderMessagesBecomePartOfTheError) {
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(4, 6, CV_8U, cv::Scalar(255)), png);
  const size_t idat =
      std::search(png.begin(), png.end(), std::begin("IDAT"), std::end("IDAT") - 1) - png.begin();
  for (size_t i = idat + 4; i < idat + 10; ++i) png[i] = 0xff;  // the zlib header and the first bytes
  ::testing::internal::CaptureStderr();
  EXPECT_THROW(DecodeImage(png, "broken"), InputError);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace lidarshop
