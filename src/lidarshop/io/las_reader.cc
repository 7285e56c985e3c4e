#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/las_format.h"
#include "lidarshop/io/las_header.h"
#include "lidarshop/io/laz.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {

namespace {

// The source records the writers carry on: the coordinate reference system and the specification's own
// descriptions. Others (LASzip, COPC, waveform descriptors, vendors' records) describe a layout or an index
// of the file they came with, which a written file no longer has.
bool KeepRecord(const SourceRecord& record) {
  if (record.user_id == "LASF_Projection") return true;
  if (record.user_id == "liblas" && record.record_id == 2112) return true;  // an older WKT writer's record
  return record.user_id == "LASF_Spec" &&
         (record.record_id == 0 || record.record_id == 3 || record.record_id == 4);
}

// One attribute channel, created on the first point whose value is not 0.
template <typename T>
struct AttributeColumn {
  const char* name;
  int type;
  cv::Mat values;
  void Set(Scan* scan, int64_t i, T value) {
    if (value == T{}) return;  // NaN is not 0 and is kept
    if (values.empty()) values = cv::Mat(1, scan->cols, type, cv::Scalar::all(0));
    values.at<T>(0, static_cast<int>(i)) = value;
  }
  void MoveInto(Scan* scan) {
    if (!values.empty()) scan->attributes[name] = std::move(values);
  }
};

}  // namespace

namespace {

// The point records, a chunk at a time: from memory (a whole file, or LAZ's decoded records) or read from the
// file, so that parsing a file of 100 M points holds one chunk of it, not the file. Parsing walks the records
// in order, twice.
class RecordChunks {
 public:
  RecordChunks(const char* records, int record_length) : memory_(records), record_length_(record_length) {}
  RecordChunks(const std::string& path, int64_t offset, int64_t count, int record_length)
      : path_(path),
        in_(path, std::ios::binary),
        offset_(offset),
        count_(count),
        record_length_(record_length) {
    if (!in_) ThrowInputError(path, "the point records", "file", "cannot be opened");
  }
  const char* Record(int64_t i) {
    if (memory_ != nullptr) return memory_ + i * record_length_;
    if (i < first_ || i >= first_ + loaded_) Load(i);
    return buffer_.data() + (i - first_) * record_length_;
  }

 private:
  static constexpr int64_t kChunkRecords = 1 << 16;
  void Load(int64_t i) {
    first_ = i;
    loaded_ = std::min(kChunkRecords, count_ - i);
    buffer_.resize(static_cast<size_t>(loaded_ * record_length_));
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset_ + i * record_length_));
    if (!in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()))) {
      // The header's count was checked against the file's size: the file changed while it was read.
      ThrowInputError(path_, fmt::format("point {} (byte {})", i, offset_ + i * record_length_),
                      "point record", "the file ended before its points did (it changed while it was read?)");
    }
  }
  const char* memory_ = nullptr;
  std::string path_;
  std::ifstream in_;
  int64_t offset_ = 0, count_ = 0;
  int record_length_ = 0;
  std::vector<char> buffer_;
  int64_t first_ = 0, loaded_ = 0;
};

Scan ParsePoints(las::LasHeader header, RecordChunks& records, const std::string& file,
                 std::vector<std::string>* warnings);

}  // namespace

Scan ParseLas(const std::string& bytes, const std::string& file, std::vector<std::string>* warnings) {
  las::LasHeader header = las::ParseHeader(bytes, file);
  if (header.count > 0) io_internal::CheckScanSize(1, header.count, file, "header: Number of Point Records");
  // LAZ: decoded into the records an uncompressed file would hold (error places are then point indices).
  std::string decoded;
  if (header.laz) {
    decoded = laz::DecodeLazPoints(header.laszip_payload, bytes, header.offset_to_points, header.count,
                                   header.format, header.record_length, file);
  }
  RecordChunks records(header.laz ? decoded.data() : bytes.data() + header.offset_to_points,
                       header.record_length);
  return ParsePoints(std::move(header), records, file, warnings);
}

Scan ReadLas(const std::string& path, std::vector<std::string>* warnings) {
  // A LAS file's points are read a chunk at a time (a LAZ file's are decoded from the whole file, as before):
  // the header and its records first, the extended records from the tail, then the points in order.
  const int64_t file_size = CheckRegularFile(path);
  const std::string prefix = las::ReadHeaderPrefix(path, file_size);
  las::LasHeader header = las::ParseHeader(prefix, path, file_size);
  if (header.laz) return ParseLas(io_internal::ReadFileToString(path), path, warnings);
  if (header.count > 0) io_internal::CheckScanSize(1, header.count, path, "header: Number of Point Records");
  las::ReadExtendedRecordsFromFile(path, file_size, prefix, &header);
  RecordChunks records(path, header.offset_to_points, header.count, header.record_length);
  return ParsePoints(std::move(header), records, path, warnings);
}

namespace {

Scan ParsePoints(las::LasHeader header, RecordChunks& records, const std::string& file,
                 std::vector<std::string>* warnings) {
  const int64_t count = header.count;
  const int format = header.format;
  const bool legacy = las::IsLegacyFormat(format);
  const bool rgb = las::HasRgb(format);
  const int extra_bytes = header.record_length - las::PointRecordSize(format);
  auto record = [&](int64_t i) { return records.Record(i); };
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
  bool rgb_is_8bit_times_257 = true;
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
      for (int c = 0; c < 3; ++c) {
        const uint16_t value = las::Load<uint16_t>(p + las::RgbOffset(format) + 2 * c);
        max_rgb = std::max(max_rgb, value);
        rgb_is_8bit_times_257 &= value % 257 == 0;
      }
    }
  }
  const double step =
      std::min({std::abs(header.scale[0]), std::abs(header.scale[1]), std::abs(header.scale[2])});
  const Eigen::Vector3d origin =
      count > 0 ? io_internal::CloudOrigin(low, high, step) : Eigen::Vector3d::Zero();
  if (count > 0 && !io_internal::FloatKeepsStep(low - origin, high - origin, step)) {
    header.warnings.push_back(fmt::format(
        "{}: the points span {:.0f} m; relative to their centre a float keeps {:.2g} m, coarser than the "
        "file's step of {:.2g} m",
        file, (high - low).maxCoeff(), io_internal::FloatStepAt((high - low).maxCoeff() / 2), step));
  }
  // 16-bit colour is divided by 257 (65535 -> 255); files with 8-bit values in the 16-bit fields are kept.
  const bool eight_bit_color = max_rgb <= 255;

  // Intensity is optional in LAS (0 = not recorded): a file whose intensities are all 0 has none.
  Scan scan = MakeScan(1, static_cast<int>(count), rgb, /*with_intensity=*/any_intensity);
  scan.world_from_scanner.topRightCorner<3, 1>() = origin;
  if (any_label) scan.label = cv::Mat(1, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  if (any_synthetic) scan.synthesized = cv::Mat(1, scan.cols, CV_8U, cv::Scalar(0));
  AttributeColumn<double> gps_time{kLasGpsTime, CV_64F};
  AttributeColumn<uint8_t> return_number{kLasReturnNumber, CV_8U}, returns{kLasNumberOfReturns, CV_8U},
      class_flags{kLasClassFlags, CV_8U}, channel{kLasScannerChannel, CV_8U},
      direction{kLasScanDirection, CV_8U}, edge{kLasEdgeOfFlightLine, CV_8U}, user_data{kLasUserData, CV_8U};
  AttributeColumn<float> scan_angle{kLasScanAngle, CV_32F};
  AttributeColumn<uint16_t> source_id{kLasPointSourceId, CV_16U}, nir{kLasNir, CV_16U};
  cv::Mat rgb16 =
      rgb && !rgb_is_8bit_times_257 ? cv::Mat(1, scan.cols, CV_16UC3, cv::Scalar::all(0)) : cv::Mat();
  cv::Mat extra;
  if (extra_bytes > 0 && extra_bytes <= CV_CN_MAX) extra = cv::Mat(1, scan.cols, CV_8UC(extra_bytes));
  if (extra_bytes > CV_CN_MAX) {
    header.warnings.push_back(
        fmt::format("{}: the {} extra bytes of each point are left out (at most {} are kept)", file,
                    extra_bytes, CV_CN_MAX));
  }
  uint8_t* valid = scan.valid.ptr<uint8_t>(0);
  cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(0);
  float* intensity = any_intensity ? scan.intensity.ptr<float>(0) : nullptr;
  for (int64_t i = 0; i < count; ++i) {
    const char* p = record(i);
    // Every record is a point: in a LAS file (0, 0, 0) is a coordinate like any other.
    valid[i] = kValid;
    point[i] = cv::Vec3f(static_cast<float>(coordinate(p, 0) - origin.x()),
                         static_cast<float>(coordinate(p, 1) - origin.y()),
                         static_cast<float>(coordinate(p, 2) - origin.z()));
    if (any_intensity) intensity[i] = las::Load<uint16_t>(p + las::point::kIntensity) / 65535.0f;
    if (rgb) {
      cv::Vec3b& color = scan.color.at<cv::Vec3b>(0, static_cast<int>(i));
      for (int c = 0; c < 3; ++c) {
        const uint16_t value = las::Load<uint16_t>(p + las::RgbOffset(format) + 2 * c);
        color[c] = static_cast<uint8_t>(eight_bit_color ? value : (value + 128) / 257);
        if (!rgb16.empty()) rgb16.at<cv::Vec3w>(0, static_cast<int>(i))[c] = value;
      }
    }
    if (any_label) scan.label.at<int32_t>(0, static_cast<int>(i)) = label_of(p);
    if (any_synthetic && synthetic(p)) scan.synthesized.at<uint8_t>(0, static_cast<int>(i)) = kValid;
    const uint8_t return_byte = static_cast<uint8_t>(p[las::point::kReturnByte]);
    const uint8_t class_byte = static_cast<uint8_t>(p[las::point::kClassByte]);
    if (legacy) {
      return_number.Set(&scan, i, return_byte & 7);
      returns.Set(&scan, i, (return_byte >> 3) & 7);
      direction.Set(&scan, i, (return_byte >> 6) & 1);
      edge.Set(&scan, i, (return_byte >> 7) & 1);
      class_flags.Set(&scan, i, static_cast<uint8_t>((class_byte >> 6) << 1));  // key-point, withheld
      scan_angle.Set(&scan, i, static_cast<float>(static_cast<int8_t>(p[las::point::kScanAngleRank])));
      user_data.Set(&scan, i, static_cast<uint8_t>(p[las::point::kUserDataLegacy]));
      source_id.Set(&scan, i, las::Load<uint16_t>(p + las::point::kPointSourceIdLegacy));
    } else {
      return_number.Set(&scan, i, return_byte & 15);
      returns.Set(&scan, i, return_byte >> 4);
      class_flags.Set(&scan, i, class_byte & 0x0E);
      channel.Set(&scan, i, (class_byte >> 4) & 3);
      direction.Set(&scan, i, (class_byte >> 6) & 1);
      edge.Set(&scan, i, (class_byte >> 7) & 1);
      user_data.Set(&scan, i, static_cast<uint8_t>(p[las::point::kUserData14]));
      scan_angle.Set(&scan, i, static_cast<float>(las::Load<int16_t>(p + las::point::kScanAngle14) * 0.006));
      source_id.Set(&scan, i, las::Load<uint16_t>(p + las::point::kPointSourceId14));
    }
    if (las::HasGpsTime(format)) {
      gps_time.Set(&scan, i,
                   las::Load<double>(p + (legacy ? las::point::kGpsTimeLegacy : las::point::kGpsTime14)));
    }
    if (las::HasNir(format)) nir.Set(&scan, i, las::Load<uint16_t>(p + las::kNirOffset));
    if (!extra.empty()) {
      std::memcpy(extra.ptr<uint8_t>(0) + i * extra_bytes, p + las::PointRecordSize(format), extra_bytes);
    }
  }
  gps_time.MoveInto(&scan);
  for (auto* column : {&return_number, &returns, &class_flags, &channel, &direction, &edge, &user_data})
    column->MoveInto(&scan);
  scan_angle.MoveInto(&scan);
  source_id.MoveInto(&scan);
  nir.MoveInto(&scan);
  if (!rgb16.empty()) scan.attributes[kLasRgb16] = rgb16;
  if (!extra.empty()) scan.attributes[kLasExtraBytes] = extra;

  std::vector<std::string> left_out;
  bool from_station = false;
  for (SourceRecord& source : header.records) {
    if (source.user_id == kLasLidarshopUserId && source.record_id == kLasFromStationRecordId) {
      from_station = true;  // the user data byte is lidarshop's from_station channel
    } else if (KeepRecord(source)) {
      scan.source_records.push_back(std::move(source));
    } else if (!(header.laz && source.user_id == "laszip encoded" &&
                 source.record_id == laz::kLazVlrRecordId)) {
      // (LASzip's record describes the compression the reading undid: nothing is lost without it.)
      left_out.push_back(fmt::format("{} {}", source.user_id, source.record_id));
    }
  }
  if (!left_out.empty()) {
    header.warnings.push_back(fmt::format(
        "{}: {} variable length record{} not kept ({}): only the coordinate "
        "system's and the specification's are carried to written files",
        file, left_out.size(), left_out.size() == 1 ? " is" : "s are", fmt::join(left_out, ", ")));
  }
  if (from_station) {
    const auto found = scan.attributes.find(kLasUserData);
    scan.from_station =
        found == scan.attributes.end() ? cv::Mat(1, scan.cols, CV_8U, cv::Scalar(0)) : found->second;
    if (found != scan.attributes.end()) scan.attributes.erase(found);
  }
  scan.source_metadata["las.point_format"] = std::to_string(format);
  scan.source_metadata["las.minor_version"] = std::to_string(header.minor_version);
  scan.source_metadata["las.global_encoding"] = std::to_string(header.global_encoding);
  scan.source_metadata["las.file_source_id"] = std::to_string(header.file_source_id);
  scan.source_metadata["las.extra_bytes"] = std::to_string(extra.empty() ? 0 : extra_bytes);
  // Intensity is kept in [0, 1]; pictures show it in the file's 16-bit units (render/render.h).
  if (any_intensity) scan.source_metadata["intensity.file_maximum"] = "65535";
  for (int axis = 0; axis < 3; ++axis) {
    // Shortest round-trip text: the writer parses back the very same doubles.
    scan.source_metadata[fmt::format("las.scale_{}", "xyz"[axis])] = fmt::format("{}", header.scale[axis]);
    scan.source_metadata[fmt::format("las.offset_{}", "xyz"[axis])] = fmt::format("{}", header.offset[axis]);
  }
  io_internal::FinishScan(&scan, /*fit_grid=*/false);
  if (warnings != nullptr) warnings->insert(warnings->end(), header.warnings.begin(), header.warnings.end());
  return scan;
}

}  // namespace

}  // namespace lidarshop
