#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/las_format.h"
#include "lidarshop/io/laz.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

struct LasHeader {
  int minor_version = 0;
  int header_size = 0;
  int64_t offset_to_points = 0;
  int format = 0;
  int record_length = 0;
  int64_t count = 0;
  // LAZ: the point format byte has LASzip's bits; the points are decoded with the laszip VLR's payload.
  bool laz = false;
  int64_t laszip_payload_at = 0;
  int laszip_payload_size = 0;
  double scale[3] = {1, 1, 1};
  double offset[3] = {0, 0, 0};
};

[[noreturn]] void Fail(const std::string& file, int byte, const char* field, const std::string& message) {
  ThrowInputError(file, fmt::format("header byte {}", byte), field, message);
}

// `bytes` holds the file or (header readers) its start up to the point data; `file_size` is the whole
// file's size (-1: bytes.size()).
LasHeader ParseHeader(const std::string& bytes, const std::string& file, int64_t file_size = -1) {
  const int64_t size = file_size < 0 ? static_cast<int64_t>(bytes.size()) : file_size;
  if (size == 0) ThrowInputError(file, "byte 0", "", "the file is empty");
  const char* h = bytes.data();
  if (size < 4 || std::memcmp(h, "LASF", 4) != 0) {
    Fail(file, 0, "File Signature",
         fmt::format("'{}' is not 'LASF': not a LAS file", io_internal::Printable(bytes.substr(0, 4))));
  }
  if (size < las::kHeaderSize12) {
    Fail(file, 0, "header",
         fmt::format("truncated: the public header block takes at least {} bytes, the file has {}",
                     las::kHeaderSize12, size));
  }
  LasHeader header;
  const int major = static_cast<uint8_t>(h[las::header::kVersionMajor]);
  header.minor_version = static_cast<uint8_t>(h[las::header::kVersionMinor]);
  if (major != 1 || header.minor_version > 4) {
    Fail(file, las::header::kVersionMajor, "Version",
         fmt::format("LAS {}.{} is not read (LAS 1.0 to 1.4)", major, header.minor_version));
  }
  const int needed = header.minor_version >= 4   ? las::kHeaderSize14
                     : header.minor_version == 3 ? las::kHeaderSize13
                                                 : las::kHeaderSize12;
  header.header_size = las::Load<uint16_t>(h + las::header::kHeaderSize);
  if (header.header_size < needed) {
    Fail(file, las::header::kHeaderSize, "Header Size",
         fmt::format("{} bytes, but LAS 1.{} needs {}", header.header_size, header.minor_version, needed));
  }
  if (header.header_size > size) {
    Fail(file, las::header::kHeaderSize, "Header Size",
         fmt::format("truncated: {} bytes of header, the file has {}", header.header_size, size));
  }
  const uint8_t format_byte = static_cast<uint8_t>(h[las::header::kPointFormat]);
  header.laz = (format_byte & las::kLazFormatBits) != 0;
  header.format = format_byte & ~las::kLazFormatBits;
  if (las::PointRecordSize(header.format) == 0) {
    Fail(file, las::header::kPointFormat, "Point Data Record Format",
         fmt::format("{} does not exist (LAS 1.4 defines 0 to 10)", header.format));
  }
  if (header.format >= 6 && header.minor_version < 4) {
    Fail(file, las::header::kPointFormat, "Point Data Record Format",
         fmt::format("{} needs LAS 1.4, the file says 1.{}", header.format, header.minor_version));
  }
  header.record_length = las::Load<uint16_t>(h + las::header::kPointRecordLength);
  if (header.record_length < las::PointRecordSize(header.format)) {
    Fail(file, las::header::kPointRecordLength, "Point Data Record Length",
         fmt::format("{} bytes, too short for point format {} ({} bytes)", header.record_length,
                     header.format, las::PointRecordSize(header.format)));
  }
  header.offset_to_points = las::Load<uint32_t>(h + las::header::kOffsetToPointData);
  if (header.offset_to_points < header.header_size || header.offset_to_points > size) {
    Fail(file, las::header::kOffsetToPointData, "Offset to Point Data",
         fmt::format("{} is not between the header's end ({}) and the file's end ({})",
                     header.offset_to_points, header.header_size, size));
  }

  // The variable length records lie between the header and the points; LASzip announces itself in one.
  const uint32_t vlrs = las::Load<uint32_t>(h + las::header::kNumberOfVlrs);
  int64_t position = header.header_size;
  for (uint32_t i = 0; i < vlrs; ++i) {
    if (position + las::kVlrHeaderSize > header.offset_to_points) {
      Fail(file, las::header::kNumberOfVlrs, "Number of Variable Length Records",
           fmt::format("{} records, but record {} at byte {} does not fit before the point data (byte {})",
                       vlrs, i, position, header.offset_to_points));
    }
    const std::string_view user_id(h + position + 2, 16);
    const uint16_t record_id = las::Load<uint16_t>(h + position + 18);
    const int64_t end = position + las::kVlrHeaderSize + las::Load<uint16_t>(h + position + 20);
    if (end > header.offset_to_points) {
      ThrowInputError(file, fmt::format("byte {}", position + 20), "VLR Record Length After Header",
                      fmt::format("variable length record {} ends at byte {}, past the start of the point "
                                  "data (byte {})",
                                  i, end, header.offset_to_points));
    }
    if (user_id.substr(0, 14) == "laszip encoded" && record_id == laz::kLazVlrRecordId) {
      header.laszip_payload_at = position + las::kVlrHeaderSize;
      header.laszip_payload_size = static_cast<int>(end - header.laszip_payload_at);
    }
    position = end;
  }

  const uint32_t legacy_count = las::Load<uint32_t>(h + las::header::kLegacyPointCount);
  header.count = legacy_count;
  if (header.minor_version >= 4) {
    const uint64_t count = las::Load<uint64_t>(h + las::header::kPointCount);
    if (count != 0 && legacy_count != 0 && count != legacy_count) {
      Fail(file, las::header::kPointCount, "Number of Point Records",
           fmt::format("{} but the legacy count says {}", count, legacy_count));
    }
    if (count > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
      Fail(file, las::header::kPointCount, "Number of Point Records", fmt::format("{} is absurd", count));
    }
    if (count != 0) header.count = static_cast<int64_t>(count);
  }
  const int count_byte = header.minor_version >= 4 && legacy_count == 0 ? las::header::kPointCount
                                                                        : las::header::kLegacyPointCount;
  if (header.count == 0) Fail(file, count_byte, "Number of Point Records", "0: the file holds no points");
  if (header.laz && header.laszip_payload_size == 0) {
    Fail(file, las::header::kPointFormat, "Point Data Record Format",
         fmt::format("{} has LASzip's compression bits but the file has no laszip encoded VLR", format_byte));
  }
  const int64_t available = size - header.offset_to_points;
  // LAZ: the decoder bounds the count by the compressed bytes (laz.h).
  if (!header.laz && header.count > available / header.record_length) {
    Fail(file, count_byte, "Number of Point Records",
         fmt::format("truncated: {} points of {} bytes need {} bytes after byte {}, the file has {}",
                     header.count, header.record_length, SaturatingBytes(header.count, header.record_length),
                     header.offset_to_points, available));
  }
  for (int axis = 0; axis < 3; ++axis) {
    header.scale[axis] = las::Load<double>(h + las::header::kScale + 8 * axis);
    header.offset[axis] = las::Load<double>(h + las::header::kOffset + 8 * axis);
    const char* names[3] = {"X Scale Factor", "Y Scale Factor", "Z Scale Factor"};
    if (!std::isfinite(header.scale[axis]) || header.scale[axis] == 0 ||
        std::abs(header.scale[axis]) > kMaxCoordinateM) {
      Fail(file, las::header::kScale + 8 * axis, names[axis],
           fmt::format("{} is not a coordinate step", header.scale[axis]));
    }
    const char* offset_names[3] = {"X Offset", "Y Offset", "Z Offset"};
    if (!(std::abs(header.offset[axis]) <= kMaxCoordinateM)) {
      Fail(file, las::header::kOffset + 8 * axis, offset_names[axis],
           fmt::format("{} is not a coordinate within {} m", header.offset[axis], kMaxCoordinateM));
    }
  }
  return header;
}

}  // namespace

Scan ParseLas(const std::string& bytes, const std::string& file) {
  const LasHeader header = ParseHeader(bytes, file);
  io_internal::CheckScanSize(1, header.count, file, "header: Number of Point Records");
  const int64_t count = header.count;
  const char* records = bytes.data() + header.offset_to_points;
  // LAZ: decoded into the records an uncompressed file would hold (error places are then point indices).
  std::string decoded;
  if (header.laz) {
    decoded = laz::DecodeLazPoints(
        std::string_view(bytes).substr(header.laszip_payload_at, header.laszip_payload_size), bytes,
        header.offset_to_points, count, header.format, header.record_length, file);
    records = decoded.data();
  }
  const int format = header.format;
  const bool legacy = las::IsLegacyFormat(format);
  const bool rgb = las::HasRgb(format);
  auto record = [&](int64_t i) { return records + i * header.record_length; };
  auto coordinate = [&](const char* p, int axis) {
    return las::Load<int32_t>(p + las::point::kX + 4 * axis) * header.scale[axis] + header.offset[axis];
  };
  auto label_of = [&](const char* p) {
    return legacy ? static_cast<uint8_t>(p[las::point::kClassByte]) & las::point::kLegacyClassMask
                  : static_cast<uint8_t>(p[las::point::kClass14]);
  };
  auto synthetic = [&](const char* p) {
    const uint8_t flags = static_cast<uint8_t>(p[las::point::kClassByte]);
    return legacy ? (flags & las::point::kLegacySyntheticBit) != 0
                  : (flags & las::point::kSyntheticFlag14) != 0;
  };

  // First pass: bounds and which channels the file holds.
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  bool any_intensity = false, any_label = false, any_synthetic = false;
  uint16_t max_rgb = 0;
  for (int64_t i = 0; i < count; ++i) {
    const char* p = record(i);
    for (int axis = 0; axis < 3; ++axis) {
      const double value = coordinate(p, axis);
      if (!(std::abs(value) <= kMaxCoordinateM)) {
        ThrowInputError(file,
                        header.laz ? fmt::format("point {}", i)
                                   : fmt::format("point {} (byte {})", i,
                                                 header.offset_to_points + i * header.record_length),
                        std::string(1, "XYZ"[axis]),
                        fmt::format("{} is not a coordinate within {} m", value, kMaxCoordinateM));
      }
      low[axis] = std::min(low[axis], value);
      high[axis] = std::max(high[axis], value);
    }
    any_intensity |= las::Load<uint16_t>(p + las::point::kIntensity) != 0;
    any_label |= label_of(p) != 0;
    any_synthetic |= synthetic(p);
    if (rgb) {
      for (int c = 0; c < 3; ++c)
        max_rgb = std::max(max_rgb, las::Load<uint16_t>(p + las::RgbOffset(format) + 2 * c));
    }
  }
  const Eigen::Vector3d origin = io_internal::CloudOrigin(low, high);
  // 16-bit colour is divided by 257 (65535 -> 255); files with 8-bit values in the 16-bit fields are kept.
  const bool eight_bit_color = max_rgb <= 255;

  // Intensity is optional in LAS (0 = not recorded): a file whose intensities are all 0 has none.
  Scan scan = MakeScan(1, static_cast<int>(count), rgb, /*with_intensity=*/any_intensity);
  scan.world_from_scanner.topRightCorner<3, 1>() = origin;
  if (any_label) scan.label = cv::Mat(1, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  if (any_synthetic) scan.synthesized = cv::Mat(1, scan.cols, CV_8U, cv::Scalar(0));
  uint8_t* valid = scan.valid.ptr<uint8_t>(0);
  cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(0);
  float* intensity = any_intensity ? scan.intensity.ptr<float>(0) : nullptr;
  for (int64_t i = 0; i < count; ++i) {
    const char* p = record(i);
    const cv::Vec3f relative(static_cast<float>(coordinate(p, 0) - origin.x()),
                             static_cast<float>(coordinate(p, 1) - origin.y()),
                             static_cast<float>(coordinate(p, 2) - origin.z()));
    if (relative == cv::Vec3f(0, 0, 0)) continue;  // no ray from the origin
    valid[i] = kValid;
    point[i] = relative;
    if (any_intensity) intensity[i] = las::Load<uint16_t>(p + las::point::kIntensity) / 65535.0f;
    if (rgb) {
      cv::Vec3b& color = scan.color.at<cv::Vec3b>(0, static_cast<int>(i));
      for (int c = 0; c < 3; ++c) {
        const uint16_t value = las::Load<uint16_t>(p + las::RgbOffset(format) + 2 * c);
        color[c] = static_cast<uint8_t>(eight_bit_color ? value : (value + 128) / 257);
      }
    }
    if (any_label) scan.label.at<int32_t>(0, static_cast<int>(i)) = label_of(p);
    if (any_synthetic && synthetic(p)) scan.synthesized.at<uint8_t>(0, static_cast<int>(i)) = kValid;
  }
  io_internal::FinishScan(&scan, /*fit_grid=*/false);
  return scan;
}

Scan ReadLas(const std::string& path) { return ParseLas(io_internal::ReadFileToString(path), path); }

ScanFileHeader io_internal::ReadLasHeader(const std::string& path) {
  const int64_t file_size = CheckRegularFile(path);
  std::string bytes = io_internal::ReadFilePrefix(path, las::kHeaderSize14);
  if (static_cast<int64_t>(bytes.size()) >= las::kHeaderSize12) {
    // The header and the variable length records up to the point data (both sizes checked by ParseHeader).
    const int64_t needed =
        std::max<int64_t>(las::Load<uint32_t>(bytes.data() + las::header::kOffsetToPointData),
                          las::Load<uint16_t>(bytes.data() + las::header::kHeaderSize));
    if (needed > static_cast<int64_t>(bytes.size()) && needed <= file_size)
      bytes = io_internal::ReadFilePrefix(path, needed);
  }
  const LasHeader header = ParseHeader(bytes, path, file_size);
  io_internal::CheckScanSize(1, header.count, path, "header: Number of Point Records");
  ScanFileHeader file;
  file.format_version = fmt::format("{} 1.{} point format {}", header.laz ? "LAZ (LAS" : "LAS",
                                    header.minor_version, header.format) +
                        (header.laz ? ")" : "");
  ScanHeader scan;
  scan.rows = 1;
  scan.cols = header.count;
  scan.points = header.count;
  // The reader's origin from the header's bounds (max x, min x, max y, ...), as it takes it from the points.
  const char* h = bytes.data();
  Eigen::Vector3d low, high;
  for (int axis = 0; axis < 3; ++axis) {
    high[axis] = las::Load<double>(h + las::header::kMaxX + 16 * axis);
    low[axis] = las::Load<double>(h + las::header::kMaxX + 16 * axis + 8);
  }
  if (low.allFinite() && high.allFinite() && (low.array() <= high.array()).all() &&
      (low.array().abs() <= kMaxCoordinateM).all() && (high.array().abs() <= kMaxCoordinateM).all()) {
    scan.world_from_scanner.topRightCorner<3, 1>() = io_internal::CloudOrigin(low, high);
  }
  scan.channels = {"xyz", "range", "intensity", "valid", "direction"};
  if (las::HasRgb(header.format)) scan.channels.push_back("rgb");
  file.scans.push_back(scan);
  return file;
}

}  // namespace lidarshop
