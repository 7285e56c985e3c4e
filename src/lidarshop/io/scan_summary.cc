#include "lidarshop/io/scan_summary.h"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/e57_image_camera.h"
#include "lidarshop/io/las.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

double Significant(double value, int digits) {
  if (!std::isfinite(value)) return value;
  return std::abs(value) < 1e-12 ? 0.0 : std::stod(fmt::format("{:.{}g}", value, digits));
}

// A pose as `info` shows it: to the nanometre (geometry's RoundedPose, as poses are reported everywhere), then
// 12 significant digits.
Eigen::Matrix4d ReadablePose(const Eigen::Matrix4d& pose) {
  Eigen::Matrix4d readable = RoundedPose(pose);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) readable(r, c) = RoundValue(readable(r, c));
  return readable;
}

std::vector<double> RoundedValues(std::vector<double> values, double (*round)(double)) {
  for (double& value : values) value = round(value);
  return values;
}

std::optional<E57MetadataSummary> SummarizeMetadata(const E57Metadata& m) {
  E57MetadataSummary summary;
  summary.guid = m.guid;
  summary.description = m.description;
  summary.sensor_vendor = m.sensor_vendor;
  summary.sensor_model = m.sensor_model;
  summary.sensor_serial_number = m.sensor_serial_number;
  summary.sensor_hardware_version = m.sensor_hardware_version;
  summary.sensor_software_version = m.sensor_software_version;
  summary.sensor_firmware_version = m.sensor_firmware_version;
  summary.acquisition_start_utc = m.acquisition_start_utc;
  if (std::isfinite(m.acquisition_start_gps_s))
    summary.acquisition_start_gps_s = RoundValue(m.acquisition_start_gps_s);
  summary.acquisition_end_utc = m.acquisition_end_utc;
  if (std::isfinite(m.acquisition_end_gps_s))
    summary.acquisition_end_gps_s = RoundValue(m.acquisition_end_gps_s);
  const bool empty = summary.guid.empty() && summary.description.empty() && summary.sensor_vendor.empty() &&
                     summary.sensor_model.empty() && summary.sensor_serial_number.empty() &&
                     summary.sensor_hardware_version.empty() && summary.sensor_software_version.empty() &&
                     summary.sensor_firmware_version.empty() && summary.acquisition_start_utc.empty() &&
                     !summary.acquisition_start_gps_s && summary.acquisition_end_utc.empty() &&
                     !summary.acquisition_end_gps_s;
  if (empty) return std::nullopt;
  return summary;
}

ScanSummary SummarizeScan(const ScanHeader& scan, int index) {
  ScanSummary summary;
  summary.index = index;
  summary.name = scan.name;
  summary.organized = scan.organized;
  auto known = [](int64_t value) { return value >= 0 ? std::optional<int64_t>(value) : std::nullopt; };
  summary.rows = known(scan.rows);
  summary.cols = known(scan.cols);
  if (scan.rows >= 0 && scan.cols >= 0) summary.cells = scan.rows * scan.cols;
  summary.points = known(scan.points);
  summary.channels = scan.channels;
  summary.coordinates = scan.coordinates;
  summary.world_from_scanner = ReadablePose(scan.world_from_scanner);
  summary.e57 = SummarizeMetadata(scan.e57);
  summary.las = scan.las;
  if (summary.las) {
    LasHeaderSummary& las = *summary.las;
    las.scale = RoundedValues(las.scale, RoundValue);
    las.offset = RoundedValues(las.offset, RoundValue);
    las.bounds.min = RoundedValues(las.bounds.min, RoundStatistic);
    las.bounds.max = RoundedValues(las.bounds.max, RoundStatistic);
    RoundForReading(&las.crs, "crs");
  }
  return summary;
}

ScanImageSummary SummarizeImageHeader(const ScanImageHeader& image, int index) {
  ScanImageSummary summary;
  summary.index = index;
  summary.name = image.name;
  summary.representation = image.projection;
  summary.width_px = image.width_px;
  summary.height_px = image.height_px;
  summary.encoding = image.encoding;
  summary.encoded_bytes = image.encoded_bytes;
  if (image.scan_index >= 0) summary.scan = image.scan_index;
  summary.world_from_camera = ReadablePose(image.world_from_camera);
  summary.e57 = SummarizeMetadata(image.e57);
  return summary;
}

// The returns per value of a histogram, {"value": count} in ascending order.
nlohmann::ordered_json Counts(const std::map<int, int64_t>& histogram) {
  nlohmann::ordered_json counts = nlohmann::ordered_json::object();
  for (const auto& [value, n] : histogram) counts[std::to_string(value)] = n;
  return counts;
}

// The stations of a file of several scans (none for one scan), from the poses to the nanometre.
std::vector<ScanStationSummary> SummarizeStations(const std::vector<ScanHeader>& scans) {
  std::vector<ScanStationSummary> stations;
  if (scans.size() < 2) return stations;
  for (size_t i = 0; i < scans.size(); ++i) {
    const Eigen::Matrix4d pose = RoundedPose(scans[i].world_from_scanner);
    auto at = [&](int r, int c) { return pose(r, c); };
    ScanStationSummary station;
    station.index = static_cast<int>(i);
    station.name = scans[i].name;
    station.position = {RoundValue(at(0, 3)), RoundValue(at(1, 3)), RoundValue(at(2, 3))};
    // The scanner's forward axis (+y) in the world is the second column; yaw = atan2(-x, y).
    station.heading_deg = RoundStatistic(std::atan2(-at(0, 1), at(1, 1)) * 180.0 / M_PI);
    stations.push_back(std::move(station));
  }
  return stations;
}

ScanFileFacts SummarizeFacts(const ScanFileHeader& header) {
  ScanFileFacts facts;
  facts.file = header.path;
  facts.format = header.format;
  facts.format_version = header.format_version;
  facts.size_bytes = header.file_size_bytes;
  facts.guid = header.guid;
  facts.created_utc = header.creation_utc;
  return facts;
}

ScanStatisticsSummary SummarizeScanStatistics(const ScanHeader& header, int index, const Scan& scan) {
  constexpr double kDegreesPerRadian = 180.0 / M_PI;
  const ScanStatistics stats = ComputeScanStatistics(scan);
  ScanStatisticsSummary summary;
  // The points decide what the header could not (an E57 grid without indexBounds): the full read's rows, cols
  // and channels win; the header's pose, name and metadata stay.
  summary.header = SummarizeScan(header, index);
  summary.header.rows = scan.rows;
  summary.header.cols = scan.cols;
  summary.header.cells = scan.num_cells();
  summary.header.channels = ChannelNames(scan);
  summary.valid = stats.valid;
  for (const auto& [name, values] : scan.attributes) summary.attributes.push_back(name);
  // Counts as `lasinfo` gives them, for clouds read from LAS: classes and return numbers of the returns.
  if (stats.from_las) {
    summary.classes = Counts(stats.returns_by_class);
    summary.returns = Counts(stats.returns_by_return_number);
    if (!scan.source_records.empty()) {
      summary.crs = LasCrsJson(scan.source_records);
      RoundForReading(&*summary.crs, "crs");
    }
  }
  if (stats.valid > 0) {
    const Eigen::AlignedBox3d& box = stats.bounds_in_world;
    summary.bounds = WorldBoundsSummary{
        "world",
        {RoundStatistic(box.min().x()), RoundStatistic(box.min().y()), RoundStatistic(box.min().z())},
        {RoundStatistic(box.max().x()), RoundStatistic(box.max().y()), RoundStatistic(box.max().z())}};
    summary.range_m = RangeSummary{RoundStatistic(stats.min_range_m), RoundStatistic(stats.max_range_m),
                                   RoundStatistic(stats.mean_range_m)};
    if (stats.min_intensity) {
      summary.intensity =
          IntensitySummary{RoundStatistic(*stats.min_intensity), RoundStatistic(*stats.max_intensity)};
    }
  }
  GridSummary& grid = summary.grid;
  grid.fitted = scan.grid.fitted;
  grid.known = !scan.grid.azimuth_rad.empty();
  if (stats.min_azimuth_deg) {
    grid.azimuth_deg = {RoundStatistic(*stats.min_azimuth_deg), RoundStatistic(*stats.max_azimuth_deg)};
    grid.elevation_deg = {RoundStatistic(*stats.min_elevation_deg), RoundStatistic(*stats.max_elevation_deg)};
    if (stats.azimuth_step_deg) grid.azimuth_step_deg = RoundStatistic(*stats.azimuth_step_deg);
    if (stats.elevation_step_deg) grid.elevation_step_deg = RoundStatistic(*stats.elevation_step_deg);
  }
  grid.rms_residual_rad = RoundRadians(scan.grid.rms_residual_rad);
  grid.max_residual_rad = RoundRadians(scan.grid.max_residual_rad);
  grid.rms_residual_deg = RoundStatistic(scan.grid.rms_residual_rad * kDegreesPerRadian);
  summary.grid_fit_rms_residual_rad = RoundRadians(scan.grid.rms_residual_rad);
  return summary;
}

E57ImageIntrinsics RoundedIntrinsics(E57ImageIntrinsics intrinsics) {
  auto apply = [](std::optional<double>& value, double (*how)(double)) {
    if (value) value = how(*value);
  };
  apply(intrinsics.focal_length_m, RoundValue);
  apply(intrinsics.pixel_width_rad, RoundRadians);
  apply(intrinsics.pixel_width_m, RoundValue);
  apply(intrinsics.pixel_height_rad, RoundRadians);
  apply(intrinsics.pixel_height_m, RoundValue);
  if (intrinsics.principal_point_px)
    intrinsics.principal_point_px = RoundedValues(*intrinsics.principal_point_px, RoundValue);
  apply(intrinsics.radius_m, RoundValue);
  apply(intrinsics.principal_y_px, RoundValue);
  return intrinsics;
}

ScanImageStatisticsSummary SummarizeImageStatistics(const ScanImageHeader& header, int index,
                                                    const E57ImageSummary& image) {
  ScanImageStatisticsSummary summary;
  // The full read's representation, size and scan win; the header's pose and metadata stay.
  summary.header = SummarizeImageHeader(header, index);
  summary.header.representation = image.representation;
  summary.header.width_px = image.width_px;
  summary.header.height_px = image.height_px;
  if (image.scan) summary.header.scan = image.scan;
  summary.decoded = image.decoded;
  summary.decode_error = image.decode_error;
  if (image.intrinsics) summary.intrinsics = RoundedIntrinsics(*image.intrinsics);
  summary.description = image.description;
  summary.has_mask = image.has_mask;
  summary.model = image.model;
  summary.camera = image.camera;
  if (summary.camera) RoundForReading(&*summary.camera, "camera");
  summary.camera_error = image.camera_error;
  summary.recolor_ready = image.recolor_ready;
  return summary;
}

template <class Summary>
std::string Brief(const Summary& summary, int64_t points) {
  const ScanFileFacts& facts = summary.facts;
  const size_t stations = summary.stations.size();
  return fmt::format("{}: {} file, {} scan(s){}, {} points, {} image(s)", facts.file,
                     facts.format_version.empty() ? facts.format : facts.format_version, summary.scans.size(),
                     stations > 0 ? fmt::format(" at {} stations", stations) : std::string(), points,
                     summary.images ? summary.images->size() : 0);
}

}  // namespace

double RoundStatistic(double value) {
  if (!std::isfinite(value)) return value;
  const double rounded = std::round(value * 1e6) / 1e6;
  return rounded == 0.0 ? 0.0 : rounded;
}

double RoundRadians(double value) { return Significant(value, 6); }

double RoundValue(double value) { return Significant(value, 12); }

void RoundForReading(nlohmann::ordered_json* json, const std::string& key) {
  auto ends_with = [&](const char* suffix) {
    const std::string s(suffix);
    return key.size() >= s.size() && key.compare(key.size() - s.size(), s.size(), s) == 0;
  };
  if (json->is_number_float()) {
    const double value = json->get<double>();
    if (!std::isfinite(value)) return;
    if (ends_with("_rad")) {
      *json = RoundRadians(value);
    } else if (key == "min" || key == "max" || key == "mean" || ends_with("_deg")) {
      *json = RoundStatistic(value);
    } else {
      *json = RoundValue(value);
    }
  } else if (json->is_object()) {
    for (auto it = json->begin(); it != json->end(); ++it) RoundForReading(&it.value(), it.key());
  } else if (json->is_array()) {
    for (auto& child : *json) RoundForReading(&child, key);
  }
}

ScanFileSummary SummarizeScanFile(const ScanFileHeader& header) {
  ScanFileSummary summary;
  summary.facts = SummarizeFacts(header);
  for (size_t i = 0; i < header.scans.size(); ++i)
    summary.scans.push_back(SummarizeScan(header.scans[i], static_cast<int>(i)));
  if (header.format == "e57") {
    summary.images.emplace();
    for (size_t i = 0; i < header.images.size(); ++i)
      summary.images->push_back(SummarizeImageHeader(header.images[i], static_cast<int>(i)));
  }
  summary.warnings = header.warnings;
  summary.stations = SummarizeStations(header.scans);
  return summary;
}

ScanFileStatistics SummarizeScanFileStatistics(const ScanFileHeader& header, const std::vector<Scan>& scans,
                                               const std::vector<E57ImageSummary>& images) {
  ScanFileStatistics summary;
  summary.facts = SummarizeFacts(header);
  std::vector<ScanHeader> scan_headers = header.scans;
  for (size_t i = scan_headers.size(); i < scans.size(); ++i) scan_headers.push_back(ScanHeaderOf(scans[i]));
  for (size_t i = 0; i < scans.size(); ++i)
    summary.scans.push_back(SummarizeScanStatistics(scan_headers[i], static_cast<int>(i), scans[i]));
  if (header.format == "e57") {
    summary.images.emplace();
    for (size_t i = 0; i < images.size(); ++i) {
      ScanImageHeader image_header;
      if (i < header.images.size()) {
        image_header = header.images[i];
      } else {  // not in the header: its name and pose from the full read
        image_header.name = images[i].name;
        image_header.world_from_camera = images[i].world_from_camera;
      }
      summary.images->push_back(SummarizeImageStatistics(image_header, static_cast<int>(i), images[i]));
    }
  }
  summary.warnings = header.warnings;
  summary.stations = SummarizeStations(scan_headers);
  return summary;
}

E57ImageSummary SummarizeE57Image(const E57Image& image, int index) {
  E57ImageSummary summary;
  summary.index = index;
  summary.name = image.name;
  summary.representation = image.projection;
  summary.width_px = image.width_px ? image.width_px : image.image.cols;
  summary.height_px = image.height_px ? image.height_px : image.image.rows;
  summary.decoded = !image.image.empty();
  summary.decode_error = image.decode_error;
  summary.world_from_camera = image.world_from_camera;
  E57ImageIntrinsics intrinsics;
  if (image.focal_length_m > 0) {
    intrinsics.focal_length_m = image.focal_length_m;
    intrinsics.pixel_width_m = image.pixel_width_m;
    intrinsics.pixel_height_m = image.pixel_height_m;
    intrinsics.principal_point_px = std::vector<double>{image.principal_x_px, image.principal_y_px};
    summary.intrinsics = intrinsics;
  } else if (image.projection == "spherical") {
    intrinsics.pixel_width_rad = image.pixel_width_rad;
    intrinsics.pixel_height_rad = image.pixel_height_rad;
    summary.intrinsics = intrinsics;
  } else if (image.projection == "cylindrical") {
    intrinsics.pixel_width_rad = image.pixel_width_rad;
    intrinsics.pixel_height_m = image.pixel_height_m;
    intrinsics.radius_m = image.radius_m;
    intrinsics.principal_y_px = image.principal_y_px;
    summary.intrinsics = intrinsics;
  }
  summary.description = image.description;
  if (image.associated_scan >= 0) summary.scan = image.associated_scan;
  summary.has_mask = !image.mask_encoded.empty();
  // The camera model (io/e57_image_camera.h): null for a visual reference or an entry missing fields.
  const std::string model_name = E57ImageModel(image);
  if (!model_name.empty()) summary.model = model_name;
  Camera model;
  std::string model_why;
  if (CameraModelOfE57Image(image, &model, &model_why)) {
    summary.camera = nlohmann::ordered_json::parse(CameraModelToJson(model));
  } else if (!model_name.empty()) {
    summary.camera_error = model_why;
  }
  return summary;
}

nlohmann::ordered_json ToJson(const ScanFileHeader& header) { return ToJson(SummarizeScanFile(header)); }

std::string BriefReport(const ScanFileSummary& summary) {
  int64_t points = 0;
  for (const ScanSummary& scan : summary.scans) points += scan.points.value_or(0);
  return Brief(summary, points);
}

std::string BriefReport(const ScanFileStatistics& summary) {
  int64_t points = 0;
  for (const ScanStatisticsSummary& scan : summary.scans) points += scan.valid;
  return Brief(summary, points);
}

}  // namespace lidarshop
