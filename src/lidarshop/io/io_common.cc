#include "lidarshop/io/io_common.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop::io_internal {

std::string ReadFileToString(const std::string& path) { return ReadRegularFile(path); }

std::string ReadFilePrefix(const std::string& path, int64_t max_bytes) {
  const int64_t size = CheckRegularFile(path);
  return ReadFileRange(path, 0, std::min(size, max_bytes), "the file's start");
}

std::string ReadFileRange(const std::string& path, int64_t offset, int64_t size, const std::string& what) {
  const int64_t file_size = CheckRegularFile(path);
  if (offset < 0 || size < 0 || offset > file_size || size > file_size - offset) {
    ThrowInputError(path, fmt::format("byte offset {}", offset), what,
                    fmt::format("truncated: {} bytes at byte {} run past the end of the file ({} bytes)",
                                size, offset, file_size));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError(path, "", "", "cannot open for reading");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(offset);
  if (size > 0 && !in.read(bytes.data(), size)) {
    ThrowInputError(path, fmt::format("byte offset {}", offset), what, "read failed");
  }
  return bytes;
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
  // Every channel a reader may fill (point, direction, range, intensity, colour, flags) and the grid fit.
  constexpr int64_t kBytesPerCell = 64;
  CheckMemoryBudget(rows * cols * kBytesPerCell,
                    fmt::format("{}: {}: a scan of {} rows x {} columns", file, place, rows, cols));
}

void CheckGridFromData(int64_t rows, int64_t cols, int64_t data_bytes, const std::string& file,
                       const std::string& place) {
  CheckScanSize(rows, cols, file, place);
  const int64_t limit =
      std::max(int64_t{1} << 22, SaturatingBytes(std::max<int64_t>(data_bytes, 0), kCellsPerDataByte));
  if (rows * cols > limit) {
    ThrowInputError(
        file, place, "size",
        fmt::format("a grid of {} rows x {} columns ({} cells) from {} bytes of data: more than {} "
                    "cells per byte; the indices are corrupt",
                    rows, cols, rows * cols, data_bytes, kCellsPerDataByte));
  }
}

void CheckScanNumbers(const Scan& scan, const std::string& file, const std::string& place) {
  const std::string problem = PoseProblem(scan.world_from_scanner, /*allow_uniform_scale=*/false);
  if (!problem.empty()) ThrowInputError(file, place, "pose", "the scanner pose " + problem);
  for (int row = 0; row < scan.rows; ++row) {
    const uint8_t* valid = scan.valid.ptr<uint8_t>(row);
    const cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(row);
    for (int col = 0; col < scan.cols; ++col) {
      if (!valid[col]) continue;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(std::abs(point[col][axis]) <= kMaxCoordinateM)) {
          ThrowInputError(
              file, fmt::format("{}: row {} column {}", place, row, col), std::string(1, "xyz"[axis]),
              fmt::format("{} is not a coordinate within {} m", point[col][axis], kMaxCoordinateM));
        }
      }
    }
  }
}

void FinishScan(Scan* scan, bool fit_grid) {
  for (int row = 0; row < scan->rows; ++row) {
    const uint8_t* valid = scan->valid.ptr<uint8_t>(row);
    cv::Vec3f* point = scan->point.ptr<cv::Vec3f>(row);
    float* range = scan->range.ptr<float>(row);
    cv::Vec3f* direction = scan->direction.ptr<cv::Vec3f>(row);
    float* intensity = scan->intensity.empty() ? nullptr : scan->intensity.ptr<float>(row);
    cv::Vec3b* color = scan->color.empty() ? nullptr : scan->color.ptr<cv::Vec3b>(row);
    for (int col = 0; col < scan->cols; ++col) {
      if (valid[col]) {
        const float norm = std::sqrt(point[col].dot(point[col]));
        range[col] = norm;
        direction[col] = norm > 0 ? point[col] / norm : cv::Vec3f(0, 0, 0);
      } else {
        point[col] = cv::Vec3f(0, 0, 0);
        range[col] = 0;
        if (intensity != nullptr) intensity[col] = 0.5f;
        direction[col] = cv::Vec3f(0, 0, 0);
        if (color != nullptr) color[col] = cv::Vec3b(0, 0, 0);
      }
    }
  }
  if (fit_grid) FitGrid(scan);
}

Eigen::Vector3d CloudOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  if (low.cwiseAbs().maxCoeff() <= kCloudFloatSafeM && high.cwiseAbs().maxCoeff() <= kCloudFloatSafeM) {
    return Eigen::Vector3d::Zero();
  }
  return ((low + high) / 2).array().round().matrix();
}

double FloatStepAt(double value) {
  const double magnitude = std::abs(value);
  if (!(magnitude >= std::numeric_limits<float>::min())) return std::numeric_limits<float>::denorm_min();
  int exponent = 0;
  std::frexp(magnitude, &exponent);  // magnitude = m * 2^exponent, m in [0.5, 1)
  return std::ldexp(1.0, exponent - 24);
}

bool FloatKeepsStep(const Eigen::Vector3d& low, const Eigen::Vector3d& high, double step_m) {
  const double largest = std::max(low.cwiseAbs().maxCoeff(), high.cwiseAbs().maxCoeff());
  return FloatStepAt(largest) / 2 <= step_m / 2 * 0.999;  // rounding to the float grid stays within step / 2
}

Eigen::Vector3d CloudOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high, double step_m) {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  if (CloudOrigin(low, high) == zero && FloatKeepsStep(low, high, step_m)) return zero;
  const Eigen::Vector3d centre = (low + high) / 2;
  const Eigen::Vector3d metre = centre.array().round().matrix();
  if (FloatKeepsStep(low - metre, high - metre, step_m)) return metre;
  return (centre / step_m).array().round().matrix() * step_m;
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
