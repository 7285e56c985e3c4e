#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "lidarshop/io/formats.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/las_format.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

bool SomeScanHasColor(const std::vector<Scan>& scans) {
  return std::any_of(scans.begin(), scans.end(), [](const Scan& scan) { return scan.has_color(); });
}
bool SomeScanHas(const std::vector<Scan>& scans, const char* attribute) {
  return std::any_of(scans.begin(), scans.end(),
                     [&](const Scan& scan) { return scan.attributes.count(attribute) > 0; });
}
// The value all scans agree on for a source metadata key, "" when one lacks it or they differ.
std::string Common(const std::vector<Scan>& scans, const std::string& key) {
  std::string value;
  for (const Scan& scan : scans) {
    const auto found = scan.source_metadata.find(key);
    if (found == scan.source_metadata.end() || (!value.empty() && found->second != value)) return "";
    value = found->second;
  }
  return value;
}
bool FromLas(const Scan& scan) { return scan.source_metadata.count("las.point_format") > 0; }

// Values past the legacy formats' fields: return numbers past 7, the overlap flag, classes past 31.
bool ExceedsLegacyRanges(const std::vector<Scan>& scans) {
  for (const Scan& scan : scans) {
    for (const char* name : {kLasReturnNumber, kLasNumberOfReturns}) {
      const auto found = scan.attributes.find(name);
      double high = 0;
      if (found != scan.attributes.end()) cv::minMaxLoc(found->second, nullptr, &high);
      if (high > 7) return true;
    }
    const auto flags = scan.attributes.find(kLasClassFlags);
    if (flags != scan.attributes.end() && cv::countNonZero(flags->second & 8) > 0) return true;  // overlap
    if (!scan.label.empty() && FromLas(scan)) {
      double high = 0;
      cv::minMaxLoc(scan.label, nullptr, &high);
      if (high > 31) return true;
    }
  }
  return false;
}

// Attributes or values only LAS 1.4's point formats 6-10 hold.
bool NeedsFormat14(const std::vector<Scan>& scans) {
  return SomeScanHas(scans, kLasScannerChannel) || SomeScanHas(scans, kLasNir) || ExceedsLegacyRanges(scans);
}

// The records written after the header: the first scan's LAS source records, the extra bytes' description
// only when those bytes are written.
std::vector<SourceRecord> RecordsToWrite(const std::vector<Scan>& scans, bool extra_bytes) {
  std::vector<SourceRecord> records;
  if (scans.empty()) return records;
  for (const SourceRecord& record : scans.front().source_records) {
    if (record.format != "las") continue;
    if (record.user_id == "LASF_Spec" && record.record_id == 4 && !extra_bytes) continue;
    if (record.payload.size() > 65535) continue;          // an extended record's size: not a VLR
    if (record.user_id == kLasLidarshopUserId) continue;  // written below when it still holds
    records.push_back(record);
  }
  if (std::any_of(scans.begin(), scans.end(), [](const Scan& scan) { return !scan.from_station.empty(); })) {
    records.push_back(
        {"las", kLasLidarshopUserId, kLasFromStationRecordId, "user data = from station",
         "The user data byte of each point is 1 + the index of the other station of the site whose "
         "measurement was resampled onto this point's ray (lidarshop fill/remove --stations), 0 = "
         "not."});
  }
  return records;
}

template <typename T>
T AttributeAt(const Scan& scan, const char* name, int row, int col, T fallback) {
  const auto found = scan.attributes.find(name);
  return found == scan.attributes.end() ? fallback : found->second.at<T>(row, col);
}

// Today's day of the year (1-366) and year, UTC, for the header.
std::pair<uint16_t, uint16_t> CreationDate() {
  const auto now = std::chrono::system_clock::now();
  const std::chrono::year_month_day date{std::chrono::floor<std::chrono::days>(now)};
  const std::chrono::sys_days first_of_year{date.year() / std::chrono::January / 1};
  const auto day = (std::chrono::sys_days{date} - first_of_year).count() + 1;
  return {static_cast<uint16_t>(day), static_cast<uint16_t>(static_cast<int>(date.year()))};
}

void PutText(std::string* bytes, int offset, const char* text, size_t width) {
  std::memcpy(bytes->data() + offset, text, std::min(std::strlen(text), width));
}

}  // namespace

int ChooseLasPointFormat(const std::vector<Scan>& scans, const LasWriteOptions& options) {
  if (options.point_format >= 0) return options.point_format;
  const bool color = SomeScanHasColor(scans);
  const bool gps = SomeScanHas(scans, kLasGpsTime);
  const bool nir = SomeScanHas(scans, kLasNir);
  const bool needs14 = NeedsFormat14(scans);
  const std::string source = Common(scans, "las.point_format");
  if (!source.empty()) {
    // The source's format, waveform packets left out (4, 5, 9, 10 are 1, 3, 6, 8 with them).
    constexpr int kWithoutWaveform[] = {0, 1, 2, 3, 1, 3, 6, 7, 8, 6, 8};
    const int format = kWithoutWaveform[std::stoi(source)];
    const bool fits = (format >= 6 || !needs14) && (format < 6 || options.minor_version >= 4) &&
                      (las::HasGpsTime(format) || !gps) && (las::HasRgb(format) || !color) &&
                      (las::HasNir(format) || !nir);
    if (fits) return format;
  }
  if (options.minor_version >= 4) return nir ? 8 : color ? 7 : 6;
  return color ? (gps ? 3 : 2) : (gps ? 1 : 0);
}

std::vector<std::string> LasAttributesNotHeld(const std::vector<Scan>& scans, int format) {
  std::vector<std::string> names;
  auto lost = [&](const char* name, bool held) {
    if (!held && SomeScanHas(scans, name)) names.push_back(name);
  };
  lost(kLasGpsTime, las::HasGpsTime(format));
  lost(kLasNir, las::HasNir(format));
  lost(kLasRgb16, las::HasRgb(format));
  lost(kLasScannerChannel, !las::IsLegacyFormat(format));
  if (las::IsLegacyFormat(format) && ExceedsLegacyRanges(scans)) {
    names.push_back(
        "values only LAS 1.4's formats 6-10 hold (return numbers past 7, the overlap flag, "
        "classes past 31: clamped)");
  }
  return names;
}

void LasWriteOptions::Check() const { Validate(*this); }

std::string LazNotWrittenMessage() { return std::string(FindScanFormat("laz")->write_refusal); }

namespace {

// Writes the LAS file of `scans` to `sink` as it is made: the header and records first, a chunk of records at a
// time, then the header again with the counts and bounds the records gave (the sink must seek). Holds the
// header and one chunk, not the file: a station's LAS is gigabytes.
void EncodeLasTo(const std::vector<Scan>& scans, const LasWriteOptions& options, const std::string& file,
                 std::ostream& sink) {
  options.Check();
  const int format = ChooseLasPointFormat(scans, options);
  const int base_record = las::PointRecordSize(format);
  const bool legacy = las::IsLegacyFormat(format);
  const bool rgb = las::HasRgb(format);
  const bool any_color = SomeScanHasColor(scans);
  if (rgb && !any_color && options.point_format >= 0) {
    // Colour nobody measured would read back as black points.
    ThrowInputError(file, "", "point_format",
                    fmt::format("point format {} stores colour but no scan has any; choose {}", format,
                                format <= 3 ? format - 2 : 6));
  }
  // Extra bytes: written when every scan carries the same number of them.
  int extra_bytes = scans.empty() ? 0 : -1;
  for (const Scan& scan : scans) {
    const auto found = scan.attributes.find(kLasExtraBytes);
    const int n = found == scan.attributes.end() ? 0 : found->second.channels();
    extra_bytes = extra_bytes < 0 || extra_bytes == n ? n : 0;
  }
  const std::vector<SourceRecord> records = RecordsToWrite(scans, extra_bytes > 0);
  const int record = base_record + extra_bytes;

  // World coordinates of every valid point first: the offsets and the bounds come from them.
  int64_t count = 0;
  for (const Scan& scan : scans) {
    CheckScan(scan);
    count += scan.CountValid();
  }
  if (count == 0) ThrowInputError(file, "", "", "no point with a return to write");
  // The world points are computed again where the records are written rather than held (24 bytes a point).
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Scan& scan : scans) {
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        const Eigen::Vector3d p = WorldPointOfCell(scan, row, col);
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
      }
    }
  }
  Eigen::Vector3d scale = Eigen::Vector3d::Constant(options.coordinate_scale_m);
  Eigen::Vector3d offset;
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(low[axis]) || !std::isfinite(high[axis])) {
      ThrowInputError(file, "", std::string(1, "xyz"[axis]), "a point coordinate is not finite");
    }
    offset[axis] = std::floor(low[axis]);
  }
  // The source's own scale and offset, when all scans share them and every point fits its integers.
  if (options.keep_source_scale) {
    Eigen::Vector3d source_scale, source_offset;
    bool found = true;
    for (int axis = 0; axis < 3 && found; ++axis) {
      const std::string s = Common(scans, fmt::format("las.scale_{}", "xyz"[axis]));
      const std::string o = Common(scans, fmt::format("las.offset_{}", "xyz"[axis]));
      found = !s.empty() && !o.empty();
      if (found) {
        source_scale[axis] = std::stod(s);
        source_offset[axis] = std::stod(o);
        found = source_scale[axis] > 0 &&
                std::abs((low[axis] - source_offset[axis]) / source_scale[axis]) < 2147483646.0 &&
                std::abs((high[axis] - source_offset[axis]) / source_scale[axis]) < 2147483646.0;
      }
    }
    if (found) {
      scale = source_scale;
      offset = source_offset;
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const double steps =
        std::max(std::abs(high[axis] - offset[axis]), std::abs(low[axis] - offset[axis])) / scale[axis];
    if (steps > 2147483646.0) {
      ThrowInputError(
          file, "", std::string(1, "xyz"[axis]),
          fmt::format("the points span {:.1f} m, more than 2^31 steps of {} m; write with "
                      "coordinate_scale_m >= {:.2g}",
                      high[axis] - offset[axis], scale[axis], (high[axis] - offset[axis]) / 2.1e9));
    }
  }

  const int header_size = options.minor_version >= 4 ? las::kHeaderSize14 : las::kHeaderSize12;
  int64_t records_size = 0;
  for (const SourceRecord& r : records)
    records_size += las::kVlrHeaderSize + static_cast<int64_t>(r.payload.size());
  const int64_t offset_to_points = header_size + records_size;
  std::string bytes(static_cast<size_t>(offset_to_points),
                    '\0');  // the header and the records before the points
  char* h = bytes.data();
  std::memcpy(h + las::header::kSignature, "LASF", 4);
  const std::string source_encoding = Common(scans, "las.global_encoding");
  const uint16_t source_bits =
      source_encoding.empty() ? 0 : static_cast<uint16_t>(std::stoi(source_encoding));
  uint16_t encoding = legacy ? 0 : las::kGlobalEncodingWkt;
  if (SomeScanHas(scans, kLasGpsTime)) encoding |= source_bits & las::kGlobalEncodingGpsStandard;
  if (options.minor_version >= 4) encoding |= source_bits & las::kGlobalEncodingWkt;
  las::Store<uint16_t>(h + las::header::kGlobalEncoding, encoding);
  const std::string source_id = Common(scans, "las.file_source_id");
  if (!source_id.empty())
    las::Store<uint16_t>(h + las::header::kFileSourceId, static_cast<uint16_t>(std::stoi(source_id)));
  h[las::header::kVersionMajor] = 1;
  h[las::header::kVersionMinor] = static_cast<char>(options.minor_version);
  PutText(&bytes, las::header::kSystemIdentifier, "lidarshop", 32);
  PutText(&bytes, las::header::kGeneratingSoftware, "lidarshop", 32);
  const auto [day, year] = CreationDate();
  las::Store<uint16_t>(h + las::header::kCreationDay, day);
  las::Store<uint16_t>(h + las::header::kCreationYear, year);
  las::Store<uint16_t>(h + las::header::kHeaderSize, static_cast<uint16_t>(header_size));
  las::Store<uint32_t>(h + las::header::kOffsetToPointData, static_cast<uint32_t>(offset_to_points));
  las::Store<uint32_t>(h + las::header::kNumberOfVlrs, static_cast<uint32_t>(records.size()));
  h[las::header::kPointFormat] = static_cast<char>(format);
  las::Store<uint16_t>(h + las::header::kPointRecordLength, static_cast<uint16_t>(record));
  // Formats 6-10 keep the legacy counts 0; 0-5 fill them while the count fits 32 bits (LAS 1.2 requires it).
  const bool legacy_counts = legacy && count <= std::numeric_limits<uint32_t>::max();
  if (!legacy_counts && options.minor_version < 4) {
    ThrowInputError(file, "", "minor_version",
                    fmt::format("{} points do not fit LAS 1.{}'s 32-bit count; write LAS 1.4", count,
                                options.minor_version));
  }
  for (int axis = 0; axis < 3; ++axis) {
    las::Store<double>(h + las::header::kScale + 8 * axis, scale[axis]);
    las::Store<double>(h + las::header::kOffset + 8 * axis, offset[axis]);
  }
  int64_t position = header_size;
  for (const SourceRecord& r : records) {
    char* v = h + position;
    PutText(&bytes, static_cast<int>(position) + las::vlr::kUserId, r.user_id.c_str(), 16);
    las::Store<uint16_t>(v + las::vlr::kRecordId, static_cast<uint16_t>(r.record_id));
    las::Store<uint16_t>(v + las::vlr::kRecordLength, static_cast<uint16_t>(r.payload.size()));
    PutText(&bytes, static_cast<int>(position) + las::vlr::kDescription, r.description.c_str(), 32);
    std::memcpy(v + las::kVlrHeaderSize, r.payload.data(), r.payload.size());
    position += las::kVlrHeaderSize + static_cast<int64_t>(r.payload.size());
  }

  // The records; the bounds are those of the stored (rounded) coordinates.
  const int max_class = legacy ? 31 : 255;
  const int max_return = legacy ? 7 : 15;
  uint64_t by_return[15] = {};
  Eigen::Vector3d stored_low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d stored_high = -stored_low;
  sink.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));  // rewritten below
  constexpr int64_t kRecordsPerChunk = int64_t{1} << 16;
  std::string chunk(static_cast<size_t>(std::min(count, kRecordsPerChunk) * record), '\0');
  char* out = chunk.data();
  auto flush = [&] {
    sink.write(chunk.data(), out - chunk.data());
    std::fill(chunk.begin(), chunk.end(), '\0');
    out = chunk.data();
  };
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& scan = scans[k];
    const bool from_las = FromLas(scan);
    // Our own scans: return 1 of 1 and the scan's index as source; a LAS file's: what it held (0 where
    // the attribute is absent: the file held 0 everywhere).
    const uint8_t default_return = from_las ? 0 : 1;
    const uint16_t default_source = from_las ? 0 : static_cast<uint16_t>(k);
    const auto extra = scan.attributes.find(kLasExtraBytes);
    const auto rgb16 = scan.attributes.find(kLasRgb16);
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        if (out == chunk.data() + chunk.size()) flush();
        const Eigen::Vector3d p = WorldPointOfCell(scan, row, col);
        for (int axis = 0; axis < 3; ++axis) {
          const double steps = std::round((p[axis] - offset[axis]) / scale[axis]);
          las::Store<int32_t>(out + las::point::kX + 4 * axis, static_cast<int32_t>(steps));
          const double stored = steps * scale[axis] + offset[axis];
          stored_low[axis] = std::min(stored_low[axis], stored);
          stored_high[axis] = std::max(stored_high[axis], stored);
        }
        // A scan without intensity writes 0, LAS's "not recorded", which reads back as no intensity.
        const double intensity =
            scan.has_intensity() ? std::clamp<double>(scan.intensity.at<float>(row, col), 0.0, 1.0) : 0.0;
        las::Store<uint16_t>(out + las::point::kIntensity,
                             static_cast<uint16_t>(std::lround(intensity * 65535)));
        int label = 0;
        if (!scan.label.empty()) label = std::clamp<int>(scan.label.at<int32_t>(row, col), 0, max_class);
        const bool synthesized = !scan.synthesized.empty() && scan.synthesized.at<uint8_t>(row, col) != 0;
        const int return_number =
            std::min<int>(AttributeAt<uint8_t>(scan, kLasReturnNumber, row, col, default_return), max_return);
        const int returns = std::min<int>(
            AttributeAt<uint8_t>(scan, kLasNumberOfReturns, row, col, default_return), max_return);
        if (return_number >= 1) ++by_return[return_number - 1];
        const uint8_t flags = AttributeAt<uint8_t>(scan, kLasClassFlags, row, col, 0);
        const uint8_t direction = AttributeAt<uint8_t>(scan, kLasScanDirection, row, col, 0) & 1;
        const uint8_t edge = AttributeAt<uint8_t>(scan, kLasEdgeOfFlightLine, row, col, 0) & 1;
        const float angle_deg = AttributeAt<float>(scan, kLasScanAngle, row, col, 0.0f);
        const uint8_t user_data = !scan.from_station.empty()
                                      ? scan.from_station.at<uint8_t>(row, col)
                                      : AttributeAt<uint8_t>(scan, kLasUserData, row, col, 0);
        const uint16_t source = AttributeAt<uint16_t>(scan, kLasPointSourceId, row, col, default_source);
        if (legacy) {
          out[las::point::kReturnByte] =
              static_cast<char>(return_number | (returns << 3) | (direction << 6) | (edge << 7));
          out[las::point::kClassByte] = static_cast<char>(
              label | (synthesized ? las::point::kLegacySyntheticBit : 0) | (((flags >> 1) & 3) << 6));
          out[las::point::kScanAngleRank] =
              static_cast<char>(std::clamp<long>(std::lround(angle_deg), -128, 127));
          out[las::point::kUserDataLegacy] = static_cast<char>(user_data);
          las::Store<uint16_t>(out + las::point::kPointSourceIdLegacy, source);
        } else {
          const uint8_t channel = AttributeAt<uint8_t>(scan, kLasScannerChannel, row, col, 0) & 3;
          out[las::point::kReturnByte] = static_cast<char>(return_number | (returns << 4));
          out[las::point::kClassByte] =
              static_cast<char>((synthesized ? las::point::kSyntheticFlag14 : 0) | (flags & 0x0E) |
                                (channel << 4) | (direction << 6) | (edge << 7));
          out[las::point::kClass14] = static_cast<char>(label);
          out[las::point::kUserData14] = static_cast<char>(user_data);
          las::Store<int16_t>(
              out + las::point::kScanAngle14,
              static_cast<int16_t>(std::clamp<long>(std::lround(angle_deg / 0.006), -32768, 32767)));
          las::Store<uint16_t>(out + las::point::kPointSourceId14, source);
        }
        if (las::HasGpsTime(format)) {
          las::Store<double>(out + (legacy ? las::point::kGpsTimeLegacy : las::point::kGpsTime14),
                             AttributeAt<double>(scan, kLasGpsTime, row, col, 0.0));
        }
        if (rgb && scan.has_color()) {
          const cv::Vec3b& c = scan.color.at<cv::Vec3b>(row, col);
          for (int i = 0; i < 3; ++i) {
            const uint16_t value = rgb16 != scan.attributes.end() ? rgb16->second.at<cv::Vec3w>(row, col)[i]
                                                                  : static_cast<uint16_t>(c[i] * 257);
            las::Store<uint16_t>(out + las::RgbOffset(format) + 2 * i, value);
          }
        }
        if (las::HasNir(format)) {
          las::Store<uint16_t>(out + las::kNirOffset, AttributeAt<uint16_t>(scan, kLasNir, row, col, 0));
        }
        if (extra_bytes > 0) {
          std::memcpy(out + base_record,
                      extra->second.ptr<uint8_t>(row) + static_cast<size_t>(col) * extra_bytes, extra_bytes);
        }
        out += record;
      }
    }
  }
  if (legacy_counts) {
    las::Store<uint32_t>(h + las::header::kLegacyPointCount, static_cast<uint32_t>(count));
    for (int r = 0; r < 5; ++r) {
      las::Store<uint32_t>(h + las::header::kLegacyPointsByReturn + 4 * r,
                           static_cast<uint32_t>(by_return[r]));
    }
  }
  if (options.minor_version >= 4) {
    las::Store<uint64_t>(h + las::header::kPointCount, static_cast<uint64_t>(count));
    for (int r = 0; r < 15; ++r) las::Store<uint64_t>(h + las::header::kPointsByReturn + 8 * r, by_return[r]);
  }
  for (int axis = 0; axis < 3; ++axis) {
    las::Store<double>(h + las::header::kMaxX + 16 * axis, stored_high[axis]);
    las::Store<double>(h + las::header::kMaxX + 16 * axis + 8, stored_low[axis]);
  }
  flush();
  sink.seekp(0);
  sink.write(bytes.data(), static_cast<std::streamsize>(header_size));
}

}  // namespace

std::string EncodeLas(const std::vector<Scan>& scans, const LasWriteOptions& options,
                      const std::string& file) {
  std::stringstream bytes;
  EncodeLasTo(scans, options, file, bytes);
  return std::move(bytes).str();
}

void WriteLas(const std::string& path, const std::vector<Scan>& scans, const LasWriteOptions& options) {
  if (scans.size() > 65535) {
    ThrowInputError(path, "", "",
                    fmt::format("{} scans: a LAS point source ID holds at most 65535", scans.size()));
  }
  WriteFileAtomically(path, [&](std::ostream& stream) { EncodeLasTo(scans, options, path, stream); });
}

}  // namespace lidarshop
