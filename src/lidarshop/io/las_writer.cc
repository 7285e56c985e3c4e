#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

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

int ChooseFormat(const std::vector<Scan>& scans, const LasWriteOptions& options) {
  if (options.point_format >= 0) return options.point_format;
  const bool color = SomeScanHasColor(scans);
  if (options.minor_version >= 4) return color ? 7 : 6;
  return color ? 2 : 0;
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

void LasWriteOptions::Check() const { Validate(*this); }

std::string LazNotWrittenMessage() {
  return "LAZ is not written: lidarshop reads LAZ but has no LASzip compressor; write .las instead (the same "
         "points uncompressed; laszip -i out.las -o out.laz compresses it)";
}

std::string EncodeLas(const std::vector<Scan>& scans, const LasWriteOptions& options,
                      const std::string& file) {
  options.Check();
  const int format = ChooseFormat(scans, options);
  const int record = las::PointRecordSize(format);
  const bool legacy = las::IsLegacyFormat(format);
  const bool rgb = las::HasRgb(format);
  const bool any_color = SomeScanHasColor(scans);
  if (rgb && !any_color && options.point_format >= 0) {
    // Colour nobody measured would read back as black points.
    ThrowInputError(file, "", "point_format",
                    fmt::format("point format {} stores colour but no scan has any; choose {}", format,
                                format <= 3 ? format - 2 : 6));
  }

  // World coordinates of every valid point first: the offsets and the bounds come from them.
  int64_t count = 0;
  for (const Scan& scan : scans) {
    CheckScan(scan);
    count += scan.CountValid();
  }
  if (count == 0) ThrowInputError(file, "", "", "no point with a return to write");
  std::vector<Eigen::Vector3d> world;
  world.reserve(static_cast<size_t>(count));
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Scan& scan : scans) {
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        world.push_back(WorldPointOfCell(scan, row, col));
        low = low.cwiseMin(world.back());
        high = high.cwiseMax(world.back());
      }
    }
  }
  const double scale = options.coordinate_scale_m;
  Eigen::Vector3d offset;
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(low[axis]) || !std::isfinite(high[axis])) {
      ThrowInputError(file, "", std::string(1, "xyz"[axis]), "a point coordinate is not finite");
    }
    offset[axis] = std::floor(low[axis]);
    const double steps = (high[axis] - offset[axis]) / scale;
    if (steps > 2147483646.0) {
      ThrowInputError(file, "", std::string(1, "xyz"[axis]),
                      fmt::format("the points span {:.1f} m, more than 2^31 steps of {} m; write with "
                                  "coordinate_scale_m >= {:.2g}",
                                  high[axis] - offset[axis], scale, (high[axis] - offset[axis]) / 2.1e9));
    }
  }

  const int header_size = options.minor_version >= 4 ? las::kHeaderSize14 : las::kHeaderSize12;
  std::string bytes(static_cast<size_t>(header_size) + static_cast<size_t>(count) * record, '\0');
  char* h = bytes.data();
  std::memcpy(h + las::header::kSignature, "LASF", 4);
  las::Store<uint16_t>(h + las::header::kGlobalEncoding, legacy ? 0 : las::kGlobalEncodingWkt);
  h[las::header::kVersionMajor] = 1;
  h[las::header::kVersionMinor] = static_cast<char>(options.minor_version);
  PutText(&bytes, las::header::kSystemIdentifier, "lidarshop", 32);
  PutText(&bytes, las::header::kGeneratingSoftware, "lidarshop", 32);
  const auto [day, year] = CreationDate();
  las::Store<uint16_t>(h + las::header::kCreationDay, day);
  las::Store<uint16_t>(h + las::header::kCreationYear, year);
  las::Store<uint16_t>(h + las::header::kHeaderSize, static_cast<uint16_t>(header_size));
  las::Store<uint32_t>(h + las::header::kOffsetToPointData, static_cast<uint32_t>(header_size));
  las::Store<uint32_t>(h + las::header::kNumberOfVlrs, 0);
  h[las::header::kPointFormat] = static_cast<char>(format);
  las::Store<uint16_t>(h + las::header::kPointRecordLength, static_cast<uint16_t>(record));
  // Formats 6-10 keep the legacy counts 0; 0-5 fill them while the count fits 32 bits (LAS 1.2 requires it).
  const bool legacy_counts = legacy && count <= std::numeric_limits<uint32_t>::max();
  if (!legacy_counts && options.minor_version < 4) {
    ThrowInputError(file, "", "minor_version",
                    fmt::format("{} points do not fit LAS 1.{}'s 32-bit count; write LAS 1.4", count,
                                options.minor_version));
  }
  if (legacy_counts) {
    las::Store<uint32_t>(h + las::header::kLegacyPointCount, static_cast<uint32_t>(count));
    las::Store<uint32_t>(h + las::header::kLegacyPointsByReturn, static_cast<uint32_t>(count));
  }
  for (int axis = 0; axis < 3; ++axis) {
    las::Store<double>(h + las::header::kScale + 8 * axis, scale);
    las::Store<double>(h + las::header::kOffset + 8 * axis, offset[axis]);
  }
  if (options.minor_version >= 4) {
    las::Store<uint64_t>(h + las::header::kPointCount, static_cast<uint64_t>(count));
    las::Store<uint64_t>(h + las::header::kPointsByReturn, static_cast<uint64_t>(count));
  }

  // The records; the bounds are those of the stored (rounded) coordinates.
  const int max_class = legacy ? 31 : 255;
  Eigen::Vector3d stored_low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d stored_high = -stored_low;
  char* out = bytes.data() + header_size;
  size_t index = 0;
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& scan = scans[k];
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        const Eigen::Vector3d& p = world[index++];
        for (int axis = 0; axis < 3; ++axis) {
          const double steps = std::round((p[axis] - offset[axis]) / scale);
          las::Store<int32_t>(out + las::point::kX + 4 * axis, static_cast<int32_t>(steps));
          const double stored = steps * scale + offset[axis];
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
        if (legacy) {
          out[las::point::kReturnByte] = 1 | (1 << 3);  // return 1 of 1
          out[las::point::kClassByte] =
              static_cast<char>(label | (synthesized ? las::point::kLegacySyntheticBit : 0));
          las::Store<uint16_t>(out + las::point::kPointSourceIdLegacy, static_cast<uint16_t>(k));
        } else {
          out[las::point::kReturnByte] = 1 | (1 << 4);
          out[las::point::kClassByte] = synthesized ? las::point::kSyntheticFlag14 : 0;
          out[las::point::kClass14] = static_cast<char>(label);
          las::Store<uint16_t>(out + las::point::kPointSourceId14, static_cast<uint16_t>(k));
        }
        if (rgb && scan.has_color()) {
          const cv::Vec3b& c = scan.color.at<cv::Vec3b>(row, col);
          for (int i = 0; i < 3; ++i) {
            las::Store<uint16_t>(out + las::RgbOffset(format) + 2 * i, static_cast<uint16_t>(c[i] * 257));
          }
        }
        out += record;
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    las::Store<double>(h + las::header::kMaxX + 16 * axis, stored_high[axis]);
    las::Store<double>(h + las::header::kMaxX + 16 * axis + 8, stored_low[axis]);
  }
  return bytes;
}

void WriteLas(const std::string& path, const std::vector<Scan>& scans, const LasWriteOptions& options) {
  if (scans.size() > 65535) {
    ThrowInputError(path, "", "",
                    fmt::format("{} scans: a LAS point source ID holds at most 65535", scans.size()));
  }
  const std::string bytes = EncodeLas(scans, options, path);
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(bytes.data(), bytes.size()); });
}

}  // namespace lidarshop
