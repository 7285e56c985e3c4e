#include "lidarshop/io/scan_header.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include <fmt/format.h>

#include "lidarshop/io/las.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"

namespace lidarshop {
namespace {

// Numbers as people read them: poses to the nanometre, which also drops the 1e-17 noise of a rotation
// (1.0000000000000002 prints as 1).
double Rounded(double value, double step = 1e-9) {
  if (!std::isfinite(value)) return value;
  const double rounded = std::round(value / step) * step;
  return rounded == 0.0 ? 0.0 : rounded;  // no -0
}

}  // namespace

std::string UtcFromGpsSeconds(double gps_seconds) {
  if (!std::isfinite(gps_seconds) || gps_seconds < 0 || gps_seconds > 1e11) return "";
  // GPS time runs ahead of UTC by the leap seconds inserted since 1980-01-06 (the GPS epoch); each entry is
  // the GPS second at which one more applies (IERS Bulletin C; none since 2017-01-01).
  static const double kLeapGpsSeconds[] = {
      46828801,  78364802,  109900803, 173059204, 252028805, 315187206, 346723207,  393984008,  425520009,
      457056010, 504489611, 551750412, 599184013, 820108814, 914803215, 1025136016, 1119744017, 1167264018};
  int leap = 0;
  for (double at : kLeapGpsSeconds) leap += gps_seconds >= at ? 1 : 0;
  constexpr double kUnixAtGpsEpoch = 315964800;  // 1980-01-06T00:00:00Z
  const std::time_t unix_seconds = static_cast<std::time_t>(std::floor(gps_seconds + kUnixAtGpsEpoch - leap));
  std::tm utc{};
  if (gmtime_r(&unix_seconds, &utc) == nullptr) return "";
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                     utc.tm_hour, utc.tm_min, utc.tm_sec);
}

ScanHeader ScanHeaderOf(const Scan& scan) {
  ScanHeader header;
  header.name = scan.name;
  header.organized = scan.rows > 1;
  header.rows = scan.rows;
  header.cols = scan.cols;
  header.points = scan.num_cells();
  header.world_from_scanner = scan.world_from_scanner;
  header.channels = ChannelNames(scan);
  return header;
}

ScanFileHeader ReadScanHeader(const std::string& path) {
  CheckScanFileReadable(path);  // unknown extensions are refused as ReadScanFile refuses them
  ScanFileHeader file;
  const std::string format = FileExtension(path);
  const int64_t size = CheckRegularFile(path);
  if (format == "e57") {
    file = io_internal::ReadE57Header(path);
  } else if (format == "ply") {
    file = io_internal::ReadPlyScanHeader(path);
  } else if (format == "pcd") {
    file = io_internal::ReadPcdHeader(path);
  } else if (format == "las" || format == "laz") {
    file = io_internal::ReadLasHeader(path);
  } else if (format == "ptx") {
    file.scans = io_internal::ReadPtxHeaders(path);
    file.format_version = "PTX";
  } else {
    // XYZ and PTS have no header: what they hold is known only once read.
    ScanFile scans = ReadScanFile(path);
    for (const Scan& scan : scans.scans) file.scans.push_back(ScanHeaderOf(scan));
    file.warnings = std::move(scans.warnings);
    file.format_version = format == "pts" ? "PTS" : "XYZ";
  }
  file.path = path;
  file.format = format;
  file.file_size_bytes = size;
  return file;
}

ScanStatistics ComputeScanStatistics(const Scan& scan) {
  ScanStatistics stats;
  stats.valid = scan.CountValid();
  if (scan.source_metadata.count("las.point_format")) {
    stats.from_las = true;
    auto counts = [&](const cv::Mat& values) {
      std::map<int, int64_t> histogram;
      for (int row = 0; row < scan.rows; ++row) {
        for (int col = 0; col < scan.cols; ++col) {
          if (!scan.valid.at<uint8_t>(row, col)) continue;
          ++histogram[values.empty()            ? 0
                      : values.type() == CV_32S ? values.at<int32_t>(row, col)
                                                : values.at<uint8_t>(row, col)];
        }
      }
      return histogram;
    };
    stats.returns_by_class = counts(scan.label);
    const auto returns = scan.attributes.find(kLasReturnNumber);
    stats.returns_by_return_number = counts(returns == scan.attributes.end() ? cv::Mat() : returns->second);
  }

  double min_range = std::numeric_limits<double>::infinity(), max_range = 0, sum_range = 0;
  double min_intensity = std::numeric_limits<double>::infinity(), max_intensity = -min_intensity;
  int64_t count = 0;
  const Eigen::Matrix3d rotation = scan.world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = scan.world_from_scanner.topRightCorner<3, 1>();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
      stats.bounds_in_world.extend(rotation * Eigen::Vector3d(p[0], p[1], p[2]) + translation);
      const double range = scan.range.at<float>(row, col);
      min_range = std::min(min_range, range);
      max_range = std::max(max_range, range);
      sum_range += range;
      if (scan.has_intensity()) {
        const double intensity = scan.intensity.at<float>(row, col);
        min_intensity = std::min(min_intensity, intensity);
        max_intensity = std::max(max_intensity, intensity);
      }
      ++count;
    }
  }
  if (count > 0) {
    stats.min_range_m = min_range;
    stats.max_range_m = max_range;
    stats.mean_range_m = sum_range / count;
    if (scan.has_intensity()) {
      stats.min_intensity = min_intensity;
      stats.max_intensity = max_intensity;
    }
  }

  const std::vector<double>& azimuth = scan.grid.azimuth_rad;
  const std::vector<double>& elevation = scan.grid.elevation_rad;
  if (!azimuth.empty() && !elevation.empty()) {
    constexpr double kDegreesPerRadian = 180.0 / M_PI;
    const auto [az_min, az_max] = std::minmax_element(azimuth.begin(), azimuth.end());
    const auto [el_min, el_max] = std::minmax_element(elevation.begin(), elevation.end());
    stats.min_azimuth_deg = *az_min * kDegreesPerRadian;
    stats.max_azimuth_deg = *az_max * kDegreesPerRadian;
    stats.min_elevation_deg = *el_min * kDegreesPerRadian;
    stats.max_elevation_deg = *el_max * kDegreesPerRadian;
    if (scan.cols > 1) stats.azimuth_step_deg = (*az_max - *az_min) / (scan.cols - 1) * kDegreesPerRadian;
    if (scan.rows > 1) stats.elevation_step_deg = (*el_max - *el_min) / (scan.rows - 1) * kDegreesPerRadian;
  }
  return stats;
}

nlohmann::ordered_json MatrixJson(const Eigen::Matrix4d& matrix) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back(
        {Rounded(matrix(r, 0)), Rounded(matrix(r, 1)), Rounded(matrix(r, 2)), Rounded(matrix(r, 3))});
  }
  return rows;
}

}  // namespace lidarshop
