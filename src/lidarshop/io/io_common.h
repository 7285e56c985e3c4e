// Helpers shared by the scan readers and writers (internal to the io module).
#pragma once

#include <cstdint>
#include <string>

#include "lidarshop/scan/scan.h"

namespace lidarshop::io_internal {

// Reads a whole file into memory; throws InputError naming the file when it cannot be opened or read.
std::string ReadFileToString(const std::string& path);

// Throws InputError naming `file` and `place` when rows x cols is negative or more than kMaxScanCells, before
// anything is allocated.
void CheckScanSize(int64_t rows, int64_t cols, const std::string& file, const std::string& place);

// After a reader has filled `valid` and `point`: sets range = |point| and direction = point / range of valid
// cells, clears invalid cells (point 0, range 0, intensity 0.5, colour 0) and, when `fit_grid`, fits the
// angular grid so that every cell gets a direction (FitGrid). A scan without any return keeps zero
// directions.
void FinishScan(Scan* scan, bool fit_grid);

// An image as CV_8UC3 RGB (grey and RGBA converted, 16-bit scaled down), for mesh textures.
cv::Mat TextureToRgb8(const cv::Mat& image);

// `value` as an int32 when it is a whole number in range, else `fallback` (no undefined float-to-int casts on
// hostile input).
inline int32_t ToInt32(double value, int32_t fallback = -1) {
  return value >= -2147483648.0 && value <= 2147483647.0 &&
                 value == static_cast<double>(static_cast<int64_t>(value))
             ? static_cast<int32_t>(value)
             : fallback;
}

// Appends the shortest decimal form of `value` that reads back to the same float/double (std::to_chars).
void AppendNumber(std::string* out, float value);
void AppendNumber(std::string* out, double value);
void AppendNumber(std::string* out, int64_t value);

}  // namespace lidarshop::io_internal
