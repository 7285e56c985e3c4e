#include "lidarshop/io/image_io.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

// OpenCV's BGR(A) <-> lidarshop's RGB(A); the conversion is its own inverse.
cv::Mat SwapRedBlue(const cv::Mat& image) {
  cv::Mat swapped;
  if (image.channels() == 3) {
    cv::cvtColor(image, swapped, cv::COLOR_BGR2RGB);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, swapped, cv::COLOR_BGRA2RGBA);
  } else {
    swapped = image;
  }
  return swapped;
}

// OpenCV picks a decoder by the content, not the name, and some of its decoders abort on malformed input
// (gdcm asserts on a broken DICOM). Only the formats lidarshop writes and documents reach OpenCV: PNG, JPEG,
// TIFF, OpenEXR and BMP. A PNG must also end with its IEND chunk: libpng reports a truncated file on stderr
// itself before OpenCV fails, which would make two lines of one error.
void CheckImageBytes(const std::string& path, int64_t size) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8] = {};
  in.read(reinterpret_cast<char*>(head), 8);
  auto starts = [&](std::initializer_list<unsigned char> magic) {
    return size >= static_cast<int64_t>(magic.size()) && std::equal(magic.begin(), magic.end(), head);
  };
  const bool png = starts({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'});
  if (!png && !starts({0xff, 0xd8, 0xff}) && !starts({'I', 'I', 42, 0}) && !starts({'M', 'M', 0, 42}) &&
      !starts({0x76, 0x2f, 0x31, 0x01}) && !starts({'B', 'M'})) {
    ThrowInputError(path, "byte 0", "signature", "not a PNG, JPEG, TIFF, OpenEXR or BMP image");
  }
  if (!png) return;
  static const char kEnd[] = "IEND\xae\x42\x60\x82";
  char tail[8] = {};
  in.seekg(size - 8);
  in.read(tail, 8);
  if (size < 57 || !in || std::memcmp(tail, kEnd, 8) != 0) {
    ThrowInputError(path, "", "", "a truncated PNG (the file does not end with the IEND chunk)");
  }
}

}  // namespace

cv::Mat ReadImage(const std::string& path) {
  CheckImageBytes(path, CheckRegularFile(path));
  // OpenCV refuses images past this many pixels from the header, before decoding; keep it within the budget
  // (8 bytes a pixel: 4 channels of 16 bits). Read once by OpenCV, so set before the first imread.
  static const bool limited = [] {
    const int64_t pixels = std::min<int64_t>(int64_t{1} << 30, MemoryBudgetBytes() / 8);
    return setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(pixels).c_str(), 0) == 0;
  }();
  (void)limited;
  if (FileExtension(path) == "exr") {
    // OpenCV 4.6 reads EXR only when this is set before the first use.
    setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  }
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& error) {
    // error.err is OpenCV's message without its multi-line location banner.
    ThrowInputError(
        path, "", "",
        fmt::format("not a readable image (OpenCV: {}; images are limited to {} pixels)", error.err,
                    getenv("OPENCV_IO_MAX_IMAGE_PIXELS") ? getenv("OPENCV_IO_MAX_IMAGE_PIXELS") : "?"));
  }
  if (image.empty()) ThrowInputError(path, "", "", "not a readable image");
  return SwapRedBlue(image);
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  if (image.empty()) ThrowInputError(path, "", "", "cannot write an empty image");
  const std::string extension = FileExtension(path);
  if (extension == "exr") setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  if ((extension == "jpg" || extension == "jpeg") && image.depth() != CV_8U) {
    ThrowInputError(path, "", "", "JPEG holds 8-bit images only; use .png (16-bit) or .exr (float)");
  }
  if (extension == "png" && image.depth() != CV_8U && image.depth() != CV_16U) {
    ThrowInputError(path, "", "", "PNG holds 8- or 16-bit images only; use .exr or .tif for float images");
  }
  const cv::Mat bgr = SwapRedBlue(image);
  WritePathAtomically(path, [&](const std::string& temporary) {
    try {
      return cv::imwrite(temporary, bgr);
    } catch (const cv::Exception& error) {
      ThrowInputError(path, "", "", fmt::format("cannot write the image ({})", error.what()));
    }
  });
}

cv::Mat DecodeImage(const std::vector<uint8_t>& bytes, const std::string& what) {
  if (bytes.empty()) ThrowInputError(what, "", "", "empty image data");
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& error) {
    ThrowInputError(what, "", "", fmt::format("not a decodable image ({})", error.what()));
  }
  if (image.empty()) ThrowInputError(what, "", "", "not a decodable image");
  return SwapRedBlue(image);
}

cv::Mat ReadMask(const std::string& path, cv::Size expected, const std::string& what) {
  cv::Mat mask = ReadImage(path);
  if (mask.depth() != CV_8U) ThrowInputError(path, "", "", "a mask must be an 8-bit image");
  if (mask.size() != expected) {
    ThrowInputError(path, "", "",
                    fmt::format("the mask is {}x{} but {} is {}x{}", mask.cols, mask.rows, what,
                                expected.width, expected.height));
  }
  if (mask.channels() > 1) {
    std::vector<cv::Mat> planes;
    cv::split(mask, planes);
    mask = planes[0];
    for (size_t c = 1; c < std::min<size_t>(planes.size(), 3); ++c) cv::max(mask, planes[c], mask);
  }
  cv::Mat binary;
  cv::threshold(mask, binary, 127, 255, cv::THRESH_BINARY);
  return binary;
}

}  // namespace lidarshop
