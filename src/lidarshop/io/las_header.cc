// The LAS header and records (las_header.h) and what `info` shows of them (io_internal::ReadLasHeader).
#include "lidarshop/io/las_header.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string_view>

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
namespace las {
namespace {

std::string FixedText(const char* p, size_t width) {
  std::string text(p, width);
  text.resize(std::strlen(text.c_str()));
  return io_internal::Printable(text);
}

[[noreturn]] void Fail(const std::string& file, int byte, const char* field, const std::string& message) {
  ThrowInputError(file, fmt::format("header byte {}", byte), field, message);
}

// Smaller steps are not coordinate steps but corrupt headers (a subnormal scale maps every point onto the
// offset).
constexpr double kMinLasScale = 1e-12;

// LAS 1.4's extended variable length records, after the points (coordinate systems as WKT live there), from
// `region`: the file's bytes from `region_offset` to its end (`size`). Records that do not fit are left out with
// a warning.
void ReadExtendedRecordsIn(std::string_view region, int64_t region_offset, uint64_t first, uint32_t count,
                           const std::string& file, int64_t size, LasHeader* header) {
  if (count == 0) return;
  // The file's byte `position` (within the region: checked by `header_fits` before any read).
  const auto at = [&](uint64_t position) {
    return region.data() + (position - static_cast<uint64_t>(region_offset));
  };
  uint64_t position = first;
  for (uint32_t i = 0; i < count; ++i) {
    // Both sides of each comparison stay within [0, size]: no unsigned wrap-around can let a record pass.
    const bool header_fits =
        position >= static_cast<uint64_t>(std::max(header->offset_to_points, region_offset)) &&
        position <= static_cast<uint64_t>(size) &&
        static_cast<uint64_t>(size) - position >= las::kEvlrHeaderSize;
    const uint64_t length =
        header_fits ? las::Load<uint64_t>(at(position) + las::vlr::kRecordLength) : uint64_t{0};
    if (!header_fits || length > static_cast<uint64_t>(size) - position - las::kEvlrHeaderSize) {
      header->warnings.push_back(fmt::format(
          "{}: extended variable length record {} at byte {} does not fit in the file ({} bytes); left out "
          "with the {} after it",
          file, i, position, size, count - i - 1));
      return;
    }
    SourceRecord record;
    record.format = "las";
    record.user_id = FixedText(at(position) + las::vlr::kUserId, 16);
    record.record_id = las::Load<uint16_t>(at(position) + las::vlr::kRecordId);
    record.description = FixedText(at(position) + 28, 32);
    record.payload.assign(at(position) + las::kEvlrHeaderSize, static_cast<size_t>(length));
    header->records.push_back(std::move(record));
    position += las::kEvlrHeaderSize + length;
  }
}

// The extended records of a whole file in `bytes`.
void ReadExtendedRecords(const std::string& bytes, const std::string& file, int64_t size, LasHeader* header) {
  if (header->minor_version < 4 || static_cast<int64_t>(bytes.size()) != size) return;
  ReadExtendedRecordsIn(bytes, 0, las::Load<uint64_t>(bytes.data() + las::header::kFirstEvlr),
                        las::Load<uint32_t>(bytes.data() + las::header::kNumberOfEvlrs), file, size, header);
}

}  // namespace

LasHeader ParseHeader(const std::string& bytes, const std::string& file, int64_t file_size) {
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

  header.global_encoding = las::Load<uint16_t>(h + las::header::kGlobalEncoding);
  header.file_source_id = las::Load<uint16_t>(h + las::header::kFileSourceId);

  // The variable length records lie between the header and the points; LASzip announces itself in one.
  const uint32_t vlrs = las::Load<uint32_t>(h + las::header::kNumberOfVlrs);
  int64_t position = header.header_size;
  const int64_t vlr_end = std::min<int64_t>(header.offset_to_points, static_cast<int64_t>(bytes.size()));
  for (uint32_t i = 0; i < vlrs; ++i) {
    const int64_t end =
        position + las::kVlrHeaderSize > vlr_end
            ? -1
            : position + las::kVlrHeaderSize + las::Load<uint16_t>(h + position + las::vlr::kRecordLength);
    if (end < 0 || end > vlr_end) {
      // Writers that miscount their records are common (PDAL keeps such files readable); the points are
      // found by the offset to the point data, not by the records.
      header.warnings.push_back(fmt::format(
          "{}: the header announces {} variable length records, but record {} at byte {} does not fit "
          "before the point data (byte {}); read the first {}",
          file, vlrs, i, position, header.offset_to_points, i));
      break;
    }
    SourceRecord record;
    record.format = "las";
    record.user_id = FixedText(h + position + las::vlr::kUserId, 16);
    record.record_id = las::Load<uint16_t>(h + position + las::vlr::kRecordId);
    record.description = FixedText(h + position + las::vlr::kDescription, 32);
    record.payload.assign(h + position + las::kVlrHeaderSize, h + end);
    if (record.user_id == "laszip encoded" && record.record_id == laz::kLazVlrRecordId) {
      header.laszip_payload.assign(record.payload.begin(), record.payload.end());
    }
    header.records.push_back(std::move(record));
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
  if (header.laz && header.laszip_payload.empty()) {
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
    if (!std::isfinite(header.scale[axis]) || std::abs(header.scale[axis]) < kMinLasScale ||
        std::abs(header.scale[axis]) > kMaxCoordinateM) {
      Fail(file, las::header::kScale + 8 * axis, names[axis],
           fmt::format("{} is not a coordinate step", header.scale[axis]));
    }
    const char* offset_names[3] = {"X Offset", "Y Offset", "Z Offset"};
    if (!(std::abs(header.offset[axis]) <= kMaxCoordinateM)) {
      Fail(file, las::header::kOffset + 8 * axis, offset_names[axis],
           fmt::format("{} is not a coordinate within {} m", header.offset[axis], kMaxCoordinateM));
    }
    // The header's bounds must be reachable with 32-bit steps of this scale (a scale of 5e-324 turned every
    // point into the offset). Bounds that are not numbers, or all 0 (never filled in), are left to the
    // points' own check.
    const double bound_high = las::Load<double>(h + las::header::kMaxX + 16 * axis);
    const double bound_low = las::Load<double>(h + las::header::kMaxX + 16 * axis + 8);
    if (bound_low == 0 && bound_high == 0) continue;
    for (const double bound : {bound_low, bound_high}) {
      const double steps = (bound - header.offset[axis]) / header.scale[axis];
      if (header.count > 0 && std::isfinite(bound) && !(std::abs(steps) <= 2147483649.0)) {
        Fail(file, las::header::kScale + 8 * axis, names[axis],
             fmt::format("{} cannot represent the header's bound {} with 32-bit integers from the offset {}",
                         header.scale[axis], bound, header.offset[axis]));
      }
    }
  }
  ReadExtendedRecords(bytes, file, size, &header);
  return header;
}

std::string ReadHeaderPrefix(const std::string& path, int64_t file_size) {
  std::string bytes = io_internal::ReadFilePrefix(path, kHeaderSize14);
  if (static_cast<int64_t>(bytes.size()) >= kHeaderSize12) {
    // The header and the variable length records up to the point data (both sizes checked by ParseHeader).
    const int64_t needed = std::max<int64_t>(Load<uint32_t>(bytes.data() + header::kOffsetToPointData),
                                             Load<uint16_t>(bytes.data() + header::kHeaderSize));
    if (needed > static_cast<int64_t>(bytes.size()) && needed <= file_size)
      bytes = io_internal::ReadFilePrefix(path, needed);
  }
  return bytes;
}

void ReadExtendedRecordsFromFile(const std::string& path, int64_t file_size, const std::string& prefix,
                                 LasHeader* header) {
  if (header->minor_version < 4 || static_cast<int64_t>(prefix.size()) < kHeaderSize14) return;
  const uint64_t first = Load<uint64_t>(prefix.data() + header::kFirstEvlr);
  const uint32_t count = Load<uint32_t>(prefix.data() + header::kNumberOfEvlrs);
  if (count == 0) return;
  if (first < static_cast<uint64_t>(header->offset_to_points) || first > static_cast<uint64_t>(file_size)) {
    ReadExtendedRecordsIn({}, file_size, first, count, path, file_size, header);  // the warning
    return;
  }
  std::ifstream in(path, std::ios::binary);
  std::string tail(static_cast<size_t>(file_size - static_cast<int64_t>(first)), '\0');
  in.seekg(static_cast<std::streamoff>(first));
  if (!in.read(tail.data(), static_cast<std::streamsize>(tail.size())))
    ThrowInputError(path, fmt::format("byte {}", first), "extended variable length records",
                    "cannot be read");
  ReadExtendedRecordsIn(tail, static_cast<int64_t>(first), first, count, path, file_size, header);
}

}  // namespace las

ScanFileHeader io_internal::ReadLasHeader(const std::string& path) {
  const int64_t file_size = CheckRegularFile(path);
  const std::string bytes = las::ReadHeaderPrefix(path, file_size);
  const las::LasHeader header = las::ParseHeader(bytes, path, file_size);
  if (header.count > 0) io_internal::CheckScanSize(1, header.count, path, "header: Number of Point Records");
  ScanFileHeader file;
  file.format_version =
      header.laz ? fmt::format("LAZ (LAS 1.{} point format {})", header.minor_version, header.format)
                 : fmt::format("LAS 1.{} point format {}", header.minor_version, header.format);
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
    const double step =
        std::min({std::abs(header.scale[0]), std::abs(header.scale[1]), std::abs(header.scale[2])});
    scan.world_from_scanner.topRightCorner<3, 1>() = io_internal::CloudOrigin(low, high, step);
  }
  scan.channels = {"xyz", "range", "intensity", "valid", "direction"};
  if (las::HasRgb(header.format)) scan.channels.push_back("rgb");
  LasHeaderSummary& facts = scan.las.emplace();
  facts.version = fmt::format("1.{}", header.minor_version);
  facts.point_format = header.format;
  facts.record_length = header.record_length;
  facts.extra_bytes = header.record_length - las::PointRecordSize(header.format);
  facts.scale = {header.scale[0], header.scale[1], header.scale[2]};
  facts.offset = {header.offset[0], header.offset[1], header.offset[2]};
  facts.bounds = {{low[0], low[1], low[2]}, {high[0], high[1], high[2]}};
  const bool extended = header.minor_version >= 4 && las::Load<uint64_t>(h + las::header::kPointCount) != 0;
  for (int r = 0; r < (extended ? 15 : 5); ++r) {
    facts.points_by_return.push_back(
        extended ? las::Load<uint64_t>(h + las::header::kPointsByReturn + 8 * r)
                 : las::Load<uint32_t>(h + las::header::kLegacyPointsByReturn + 4 * r));
  }
  if (las::HasGpsTime(header.format)) {
    facts.gps_time = header.global_encoding & las::kGlobalEncodingGpsStandard ? "standard" : "week";
  }
  facts.file_source_id = header.file_source_id;
  for (const SourceRecord& record : header.records) {
    facts.vlrs.push_back(
        {record.user_id, record.record_id, record.description, static_cast<int64_t>(record.payload.size())});
  }
  facts.crs = LasCrsJson(header.records);
  file.warnings = header.warnings;
  file.scans.push_back(scan);
  return file;
}

}  // namespace lidarshop
