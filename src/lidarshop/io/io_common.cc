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
#include "lidarshop/scan/ray_directions.h"
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
  CheckMemoryBudget(rows * cols * kScanBytesPerCell,
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

void CheckCellsFromData(int64_t cells, int64_t bytes_per_cell, int64_t data_bytes, const std::string& file,
                        const std::string& place, const std::string& what) {
  const int64_t limit = std::min(
      kMaxScanCells,
      std::max(int64_t{1} << 22, SaturatingBytes(std::max<int64_t>(data_bytes, 0), kCellsPerDataByte)));
  if (cells < 0 || cells > limit) {
    ThrowInputError(file, place, what,
                    fmt::format("{} cells from {} bytes of data: more than the {} this file can hold ({} "
                                "cells per byte, {} at most)",
                                cells, data_bytes, limit, kCellsPerDataByte, kMaxScanCells));
  }
  CheckMemoryBudget(SaturatingBytes(cells, bytes_per_cell),
                    fmt::format("{}: {}: {} {}", file, place, cells, what));
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

namespace {

// Each valid cell's direction is its point's; a cell without a return has none (zero).
void DirectionsFromPoints(Scan* scan) {
  for (int row = 0; row < scan->rows; ++row) {
    const uint8_t* valid = scan->valid.ptr<uint8_t>(row);
    const cv::Vec3f* point = scan->point.ptr<cv::Vec3f>(row);
    const float* range = scan->range.ptr<float>(row);
    cv::Vec3f* direction = scan->direction.ptr<cv::Vec3f>(row);
    for (int col = 0; col < scan->cols; ++col) {
      direction[col] = valid[col] && range[col] > 0 ? point[col] / range[col] : cv::Vec3f(0, 0, 0);
    }
  }
}

}  // namespace

void FinishScan(Scan* scan, bool fit_grid) {
  for (int row = 0; row < scan->rows; ++row) {
    const uint8_t* valid = scan->valid.ptr<uint8_t>(row);
    cv::Vec3f* point = scan->point.ptr<cv::Vec3f>(row);
    float* range = scan->range.ptr<float>(row);
    float* intensity = scan->intensity.empty() ? nullptr : scan->intensity.ptr<float>(row);
    cv::Vec3b* color = scan->color.empty() ? nullptr : scan->color.ptr<cv::Vec3b>(row);
    for (int col = 0; col < scan->cols; ++col) {
      if (valid[col]) {
        range[col] = std::sqrt(point[col].dot(point[col]));
      } else {
        point[col] = cv::Vec3f(0, 0, 0);
        range[col] = 0;
        if (intensity != nullptr) intensity[col] = 0.5f;
        if (color != nullptr) color[col] = cv::Vec3b(0, 0, 0);
      }
    }
  }
  if (fit_grid) {
    // A fitted grid gives every cell its ray (ray_directions.h): no image is kept, nor filled to be dropped.
    scan->direction.release();
    FitGrid(scan);
    if (HasCompleteGrid(*scan)) return;
    scan->direction.create(scan->rows, scan->cols, CV_32FC3);  // no usable return: the points' own directions
  }
  DirectionsFromPoints(scan);
}

Eigen::Vector3d CloudOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  if (low.cwiseAbs().maxCoeff() <= kCloudFloatSafeM && high.cwiseAbs().maxCoeff() <= kCloudFloatSafeM) {
    return Eigen::Vector3d::Zero();
  }
  return ((low + high) / 2).array().round().matrix();
}

void PointBounds(const std::vector<Eigen::Vector3d>& points, const std::vector<uint8_t>& valid,
                 Eigen::Vector3d* low, Eigen::Vector3d* high) {
  *low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  *high = -*low;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!valid.empty() && !valid[i]) continue;
    *low = low->cwiseMin(points[i]);
    *high = high->cwiseMax(points[i]);
  }
}

Eigen::Vector3d OriginClearOfPoints(Eigen::Vector3d origin, const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<uint8_t>& valid) {
  // A point's float offset is zero only when it lies (all but) exactly on the origin; such a point can sit on
  // at most one of the candidates origin - k * step, so one of the first points.size() + 1 is free.
  constexpr double kStepM = 1.0 / 1024;
  std::vector<int64_t> taken;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!valid.empty() && !valid[i]) continue;
    const Eigen::Vector3d offset = points[i] - origin;
    if (std::abs(offset.x()) > 1e-30 || std::abs(offset.y()) > 1e-30 || offset.z() > 1e-30) continue;
    const double steps = std::round(-offset.z() / kStepM);
    if (std::abs(-offset.z() - steps * kStepM) <= 1e-30 && steps <= static_cast<double>(points.size()))
      taken.push_back(static_cast<int64_t>(steps));
  }
  std::sort(taken.begin(), taken.end());
  int64_t free_step = 0;
  for (int64_t step : taken) {
    if (step == free_step) ++free_step;
  }
  origin.z() -= static_cast<double>(free_step) * kStepM;
  return origin;
}

Eigen::Vector3d FarScanOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  if (low.cwiseAbs().maxCoeff() <= kScanRangeKeptM && high.cwiseAbs().maxCoeff() <= kScanRangeKeptM) {
    return Eigen::Vector3d::Zero();
  }
  return ((low + high) / 2).array().round().matrix();
}

Scan UnorganizedScan(const std::vector<Eigen::Vector3d>& points_in_world, const std::vector<uint8_t>& valid,
                     bool with_color, bool with_intensity, const Eigen::Matrix4d& preferred_pose) {
  LIDARSHOP_CHECK(valid.empty() || valid.size() == points_in_world.size());
  const int64_t count = static_cast<int64_t>(points_in_world.size());
  Scan scan = MakeScan(1, static_cast<int>(count), with_color, with_intensity);
  Eigen::Vector3d low, high;
  PointBounds(points_in_world, valid, &low, &high);
  const Eigen::Matrix3d world_from_scanner_rotation = preferred_pose.topLeftCorner<3, 3>();
  Eigen::Vector3d origin = preferred_pose.topRightCorner<3, 1>();
  const bool any = (low.array() <= high.array()).all();
  if (any && ((low - origin).cwiseAbs().maxCoeff() > kCloudFloatSafeM ||
              (high - origin).cwiseAbs().maxCoeff() > kCloudFloatSafeM)) {
    origin = CloudOrigin(low, high);
  }
  origin = OriginClearOfPoints(origin, points_in_world, valid);
  scan.world_from_scanner.topLeftCorner<3, 3>() = world_from_scanner_rotation;
  scan.world_from_scanner.topRightCorner<3, 1>() = origin;
  const Eigen::Matrix3d scanner_from_world_rotation = world_from_scanner_rotation.transpose();
  uint8_t* valid_out = scan.valid.ptr<uint8_t>(0);
  cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(0);
  for (int64_t i = 0; i < count; ++i) {
    if (!valid.empty() && !valid[i]) continue;
    // Not on the origin in double (OriginClearOfPoints); a float that still rounds to 0 is a point at the
    // origin, which FinishScan keeps with range 0 and no direction.
    const Eigen::Vector3f p = (scanner_from_world_rotation * (points_in_world[i] - origin)).cast<float>();
    valid_out[i] = kValid;
    point[i] = cv::Vec3f(p.x(), p.y(), p.z());
  }
  FinishScan(&scan, /*fit_grid=*/false);
  return scan;
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
