// Images as files, through OpenCV. lidarshop keeps 3-channel 8-bit images in RGB order everywhere (a scan's
// colour, rendered pictures, strokes); these functions convert to and from OpenCV's BGR at the file boundary,
// so never call cv::imread / cv::imwrite on lidarshop images directly.
//
//   .png  8-bit (1, 3, 4 channels) and 16-bit single-channel (labels, metric depth in millimetres)
//   .jpg  8-bit
//   .exr  32-bit float, any channel count (metric depth, gradients)
//   .tif  8/16/32-bit
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace lidarshop {

// Reads an image keeping its depth and channel count (IMREAD_UNCHANGED), 3/4-channel ones converted to
// RGB(A). Throws InputError when the file is missing or not an image.
cv::Mat ReadImage(const std::string& path);

// Writes an RGB(A) or single-channel image; the format follows the extension. Atomic.
void WriteImage(const std::string& path, const cv::Mat& image);

// Reads a mask picture: white (>= 128 in any colour channel) = true. Returns CV_8U 255/0 of `expected` size;
// throws InputError naming the file when it is not 8-bit or its size differs (`what` names the image it must
// match, e.g. "the scan").
cv::Mat ReadMask(const std::string& path, cv::Size expected, const std::string& what);

// Decodes an encoded JPEG/PNG buffer (e.g. an E57 image blob) into RGB.
cv::Mat DecodeImage(const std::vector<uint8_t>& bytes, const std::string& what);

}  // namespace lidarshop
