// Images as files, through OpenCV. lidarshop keeps 3-channel 8-bit images in RGB order everywhere (a scan's
// colour, rendered pictures, strokes); these functions convert to and from OpenCV's BGR at the file boundary,
// so never call cv::imread / cv::imwrite on lidarshop images directly.
//
//   .png  8-bit (1, 3, 4 channels) and 16-bit single-channel (labels, metric depth in millimetres)
//   .jpg  8-bit
//   .exr  32-bit float, any channel count (metric depth, gradients)
//   .tif  8/16/32-bit
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace lidarshop {

// OpenCV's codecs through lidarshop's plugin (util/plugin.h, loaded on first use): cv::imread, cv::imdecode,
// cv::imwrite and cv::imencode with their arguments (BGR order, OpenCV's flags). For the readers and writers
// below and the server; everything else reads and writes pictures with them.
cv::Mat CvImRead(const std::string& path, int flags);
cv::Mat CvImDecode(const cv::Mat& bytes, int flags);
bool CvImWrite(const std::string& path, const cv::Mat& image);
bool CvImEncode(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes);

// Every image lidarshop reads goes through the functions below: the size is read from the file's header
// first (ReadImageHeader) and checked against kMaxImagePixels, the size the caller expects and the memory
// budget (util/memory_budget.h), so that no decoder allocates for a size the bytes merely claim. (OpenCV's own
// limit, OPENCV_IO_MAX_IMAGE_PIXELS, is read once when the library loads, before main could set it.) What
// the image libraries print themselves (libpng and libjpeg warnings) is kept off stderr and becomes part of
// the one error when the decode fails.

// The largest image lidarshop decodes: 2^28 pixels (16384 x 16384).
constexpr int64_t kMaxImagePixels = int64_t{1} << 28;

// What an encoded image says about itself, read without decoding it: PNG's IHDR, JPEG's SOF, TIFF's first
// IFD, OpenEXR's dataWindow and channels, BMP's info header.
struct ImageHeader {
  std::string format;             // "png", "jpeg", "tiff", "exr" or "bmp"
  int64_t width = 0, height = 0;  // pixels
  int channels = 0;               // as stored (decoders may add one: a palette with transparency)
  int bytes_per_channel = 1;      // of the decoded image (4 for OpenEXR, decoded as float)
  // The decoded image, counted with one more channel and twice (the RGB conversion's copy), in bytes.
  int64_t DecodedBytes() const;
};

// Reads the header of the `size` bytes at `data`; throws InputError naming `what` when they are not a PNG,
// JPEG, TIFF, OpenEXR or BMP image or the header is truncated or names a size of 0.
ImageHeader ReadImageHeader(const uint8_t* data, size_t size, const std::string& what);

// Throws InputError naming `what` when the image of `header` is past kMaxImagePixels, differs from `expected`
// (when not empty; `expected_what` names what it must match, e.g. "the scan"), or does not fit the memory
// budget.
void CheckImageHeader(const ImageHeader& header, const std::string& what, cv::Size expected = {},
                      const std::string& expected_what = "");

// Reads an image keeping its depth and channel count (IMREAD_UNCHANGED), 3/4-channel ones converted to
// RGB(A). Throws InputError when the file is missing or not an image, or its header fails CheckImageHeader
// (with `expected`, before decoding, when given).
cv::Mat ReadImage(const std::string& path);
cv::Mat ReadImage(const std::string& path, cv::Size expected, const std::string& expected_what);

// Writes an RGB(A) or single-channel image; the format follows the extension. Atomic.
void WriteImage(const std::string& path, const cv::Mat& image);

// Reads a mask picture: white (>= 128 in any colour channel) = true. Returns CV_8U 255/0 of `expected` size;
// throws InputError naming the file when it is not 8-bit or its size differs (`what` names the image it must
// match, e.g. "the scan"); the size is compared from the header, before decoding.
cv::Mat ReadMask(const std::string& path, cv::Size expected, const std::string& what);

// Decodes an encoded JPEG/PNG buffer (e.g. an E57 image blob) into RGB(A) (`color`: always 3-channel 8-bit
// RGB), after CheckImageHeader; `what` names the buffer in errors.
cv::Mat DecodeImage(const uint8_t* data, size_t size, const std::string& what, bool color = false);
cv::Mat DecodeImage(const std::vector<uint8_t>& bytes, const std::string& what);

}  // namespace lidarshop
