#include "lidarshop/io/io_common.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop::io_internal {

std::string ReadFileToString(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) ThrowInputError(path, "", "", "cannot open the file (missing or not readable)");
  if (std::fseek(file.get(), 0, SEEK_END) != 0)
    ThrowInputError(path, "", "", "cannot seek (not a regular file?)");
  const long size = std::ftell(file.get());
  if (size < 0) ThrowInputError(path, "", "", "cannot tell the file size (not a regular file?)");
  std::rewind(file.get());
  std::string text(static_cast<size_t>(size), '\0');
  if (size > 0 && std::fread(text.data(), 1, text.size(), file.get()) != text.size()) {
    ThrowInputError(path, "", "", "read error");
  }
  return text;
}

void CheckScanSize(int64_t rows, int64_t cols, const std::string& file, const std::string& place) {
  if (rows <= 0 || cols <= 0) {
    ThrowInputError(file, place, "size", fmt::format("{} rows x {} columns is not a scan size", rows, cols));
  }
  if (rows > kMaxScanCells || cols > kMaxScanCells || rows * cols > kMaxScanCells) {
    ThrowInputError(file, place, "size",
                    fmt::format("{} rows x {} columns is more than the {} cells lidarshop accepts", rows,
                                cols, kMaxScanCells));
  }
}

void FinishScan(Scan* scan, bool fit_grid) {
  for (int row = 0; row < scan->rows; ++row) {
    const uint8_t* valid = scan->valid.ptr<uint8_t>(row);
    cv::Vec3f* point = scan->point.ptr<cv::Vec3f>(row);
    float* range = scan->range.ptr<float>(row);
    cv::Vec3f* direction = scan->direction.ptr<cv::Vec3f>(row);
    float* intensity = scan->intensity.ptr<float>(row);
    cv::Vec3b* color = scan->color.empty() ? nullptr : scan->color.ptr<cv::Vec3b>(row);
    for (int col = 0; col < scan->cols; ++col) {
      if (valid[col]) {
        const float norm = std::sqrt(point[col].dot(point[col]));
        range[col] = norm;
        direction[col] = point[col] / norm;
      } else {
        point[col] = cv::Vec3f(0, 0, 0);
        range[col] = 0;
        intensity[col] = 0.5f;
        direction[col] = cv::Vec3f(0, 0, 0);
        if (color != nullptr) color[col] = cv::Vec3b(0, 0, 0);
      }
    }
  }
  if (fit_grid) FitGrid(scan);
}

cv::Mat TextureToRgb8(const cv::Mat& image) {
  cv::Mat converted;
  if (image.channels() == 4) {
    cv::cvtColor(image, converted, cv::COLOR_RGBA2RGB);
  } else if (image.channels() == 1) {
    cv::cvtColor(image, converted, cv::COLOR_GRAY2RGB);
  } else {
    converted = image;
  }
  if (converted.depth() == CV_16U) {
    converted.convertTo(converted, CV_8U, 1.0 / 257.0);
  } else if (converted.depth() == CV_32F || converted.depth() == CV_64F) {
    converted.convertTo(converted, CV_8U, 255.0);
  } else if (converted.depth() != CV_8U) {
    converted.convertTo(converted, CV_8U);
  }
  return converted;
}

void AppendNumber(std::string* out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

void AppendNumber(std::string* out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

void AppendNumber(std::string* out, int64_t value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

}  // namespace lidarshop::io_internal
