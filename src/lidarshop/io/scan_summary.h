// What `lidarshop info` answers about a scan file, as described structs (util/options.h): the header of the
// file (ScanFileSummary, from ReadScanHeader), or the header with what reading every point adds
// (ScanFileStatistics, `info --stats`: per scan ScanStatistics, per E57 photo whether it decodes and its
// camera). The server and the Python module give the same objects.
//
// Numbers are rounded as people read them, by what they are (the summary's presentation policy: the
// Summarize functions store rounded values, ToJson writes them as they are):
//   - statistics of float32 points (bounds, range and intensity: min / max / mean) and angles in degrees to
//     1e-6 (micrometres, microdegrees): RoundStatistic;
//   - residuals and pixel sizes in radians to 6 significant digits: RoundRadians;
//   - everything else to 12 significant digits, |x| < 1e-12 to 0 (1.5, not 1.5000000000000002; UTM
//     coordinates keep 10 micrometres): RoundValue; poses are first taken to the nanometre (MatrixJson).
// Free-form parts (a LAS file's coordinate reference system, a photo's camera model) are rounded the same way
// by the key that holds each number (RoundForReading).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// --- The rounding policy (see the file comment). Non-finite values stay as they are.
double RoundStatistic(double value);  // to 1e-6, no -0
double RoundRadians(double value);    // 6 significant digits
double RoundValue(double value);      // 12 significant digits
// Every number of `json` rounded by the key that holds it (a list's elements by the list's key): keys ending
// in "_rad" as RoundRadians, "min", "max", "mean" and keys ending in "_deg" as RoundStatistic, others as
// RoundValue; `key` is the key that holds `json` itself. Integers stay as they are.
void RoundForReading(nlohmann::ordered_json* json, const std::string& key = "");

// The E57 facts of a data3D or images2D entry (E57Metadata), each left out when the file says nothing.
struct E57MetadataSummary {
  std::string guid, description;
  std::string sensor_vendor, sensor_model, sensor_serial_number;
  std::string sensor_hardware_version, sensor_software_version, sensor_firmware_version;
  std::string acquisition_start_utc;
  std::optional<double> acquisition_start_gps_s;  // GPS seconds since 1980-01-06 00:00 UTC
  std::string acquisition_end_utc;
  std::optional<double> acquisition_end_gps_s;
};

// One scan as its header describes it (ScanHeader), at `index` in the file.
struct ScanSummary {
  int index = 0;
  std::string name;  // E57 data3D name; left out when ""
  bool organized = false;
  std::optional<int64_t> rows, cols;  // the grid; null when unknown (an E57 grid without indexBounds)
  std::optional<int64_t> cells;       // rows x cols; null when either is unknown
  std::optional<int64_t> points;      // records the file stores for the scan; null when unknown
  std::vector<std::string> channels;  // as ChannelNames names them
  std::string coordinates;            // E57: "cartesian" or "spherical"; left out when ""
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  std::optional<E57MetadataSummary> e57;  // E57 only, when the entry has any of its facts
  std::optional<LasHeaderSummary> las;    // LAS only
};

// The world bounds of a scan's returns (world_from_scanner applied), metres.
struct WorldBoundsSummary {
  std::string frame = "world";
  std::vector<double> min, max;  // x, y, z
};

// Range statistics of a scan's returns, metres.
struct RangeSummary {
  double min = 0, max = 0, mean = 0;
};

// Intensity extremes of a scan's returns, in Scan::intensity's scale.
struct IntensitySummary {
  double min = 0, max = 0;
};

// A scan's angular grid (Scan::grid) as ScanStatistics gives it, degrees, with its fit's residuals.
struct GridSummary {
  bool fitted = false;  // fitted to the points (not given by the file)
  bool known = false;   // the grid's directions are known
  // [min, max] of the columns' azimuths and the rows' elevations; only when known.
  std::vector<double> azimuth_deg, elevation_deg;
  std::optional<double> azimuth_step_deg, elevation_step_deg;  // mean steps; with 2 columns / rows or more
  double rms_residual_rad = 0, max_residual_rad = 0;           // of the fit
  double rms_residual_deg = 0;
};

// One scan with what reading its points adds (`info --stats`): the header's keys first (rows, cols, cells and
// channels as the full read found them), then the statistics.
struct ScanStatisticsSummary {
  ScanSummary header;
  int64_t valid = 0;                    // returns (valid cells)
  std::vector<std::string> attributes;  // Scan::attributes' names; left out when none
  // Scans read from LAS: returns per classification and per return number ({"2": 1200, ...}) and the
  // coordinate reference system (LasCrsJson, when the file has records).
  std::optional<nlohmann::ordered_json> classes, returns, crs;
  std::optional<WorldBoundsSummary> bounds;   // null without returns
  std::optional<RangeSummary> range_m;        // with returns
  std::optional<IntensitySummary> intensity;  // with returns and an intensity channel
  GridSummary grid;
  double grid_fit_rms_residual_rad = 0;  // grid.rms_residual_rad (an earlier key)
};

// One images2D entry of an E57 file as its header describes it (ScanImageHeader), at `index`.
struct ScanImageSummary {
  int index = 0;
  std::string name;
  std::string representation;  // "pinhole", "spherical", "cylindrical" or "visual"
  int width_px = 0, height_px = 0;
  std::string encoding;  // "jpeg" or "png"
  int64_t encoded_bytes = 0;
  std::optional<int> scan;  // the scan the photo belongs to; null when none
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
  std::optional<E57MetadataSummary> e57;
};

// An E57 photo's intrinsics as the file stores them; which are there depends on the representation:
// pinhole (focal_length_m, pixel_width_m, pixel_height_m, principal_point_px), spherical (pixel_width_rad,
// pixel_height_rad), cylindrical (pixel_width_rad, pixel_height_m, radius_m, principal_y_px).
struct E57ImageIntrinsics {
  std::optional<double> focal_length_m;
  std::optional<double> pixel_width_rad;
  std::optional<double> pixel_width_m;
  std::optional<double> pixel_height_rad;
  std::optional<double> pixel_height_m;
  std::optional<std::vector<double>> principal_point_px;  // x, y
  std::optional<double> radius_m;
  std::optional<double> principal_y_px;
};

// An E57 photo read whole (`lidarshop photos`, and what `info --stats` adds to its header): whether it
// decodes, its intrinsics and camera model. Values as the file stores them (not rounded).
struct E57ImageSummary {
  int index = 0;
  std::string name;
  std::string representation;       // "pinhole", "spherical", "cylindrical" or "visual"
  int width_px = 0, height_px = 0;  // as stated, else the decoded photo's
  bool decoded = false;
  std::string decode_error;  // why it does not decode; left out when it does
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
  std::optional<E57ImageIntrinsics> intrinsics;  // pinhole with a focal length, spherical, cylindrical
  std::string description;                       // left out when ""
  std::optional<int> scan;                       // the scan the photo belongs to; left out when none
  bool has_mask = false;                         // the entry has an imageMask
  std::optional<std::string> model;              // E57ImageModel; null for a visual reference
  // The camera model (CameraModelToJson: its keys depend on the model) when the entry holds a full one, else
  // why not (camera_error, when there is a model).
  std::optional<nlohmann::ordered_json> camera;
  std::string camera_error;
  bool recolor_ready = false;  // recolour can use it as it is (recolor/e57_camera.h: SummarizeE57Images)
  std::string extracted;       // `images --extract`: the file its stored bytes went to; left out when ""
};

// The photos of an E57 file (`lidarshop images --json`).
struct E57ImagesSummary {
  std::string file;
  std::vector<E57ImageSummary> images;
};

// One photo of `info --stats`: the header's keys (representation, size and scan as the full read found them),
// then E57ImageSummary's decode, intrinsics and camera facts (rounded).
struct ScanImageStatisticsSummary {
  ScanImageSummary header;
  bool decoded = false;
  std::string decode_error;
  std::optional<E57ImageIntrinsics> intrinsics;
  std::string description;
  bool has_mask = false;
  std::optional<std::string> model;
  std::optional<nlohmann::ordered_json> camera;
  std::string camera_error;
  bool recolor_ready = false;
};

// One station of a site (a file of several scans): its position in the world (metres) and heading (degrees:
// the scanner's +y turned about the world z, positive to the left as rotate_deg's yaw).
struct ScanStationSummary {
  int index = 0;
  std::string name;
  std::vector<double> position;  // x, y, z
  double heading_deg = 0;
};

// What every file summary starts with.
struct ScanFileFacts {
  std::string file;
  std::string format;          // the extension: "ptx", "e57", "ply", "pcd", "las", "xyz", "pts"
  std::string format_version;  // ScanFileHeader::format_version; left out when ""
  int64_t size_bytes = 0;
  std::string guid;         // E57 root guid; left out when ""
  std::string created_utc;  // E57 creationDateTime; left out when ""
};

// `lidarshop info`: the file's header.
struct ScanFileSummary {
  ScanFileFacts facts;
  std::vector<ScanSummary> scans;
  std::optional<std::vector<ScanImageSummary>> images;  // E57 files only
  std::vector<std::string> warnings;                    // left out when none
  std::vector<ScanStationSummary> stations;             // files of several scans; left out otherwise
};

// `lidarshop info --stats`: the header with what reading every point adds.
struct ScanFileStatistics {
  ScanFileFacts facts;
  std::vector<ScanStatisticsSummary> scans;
  std::optional<std::vector<ScanImageStatisticsSummary>> images;  // E57 files only
  std::vector<std::string> warnings;
  std::vector<ScanStationSummary> stations;
};

// The summary of `header` (rounded; stations when it holds two scans or more).
ScanFileSummary SummarizeScanFile(const ScanFileHeader& header);

// The summary of `header` with the statistics of `scans`, the file's points (ComputeScanStatistics), and for
// an E57 file the photos read whole (`images`, SummarizeE57Images; empty for other formats). A scan or photo
// the header does not list is described from the full read (ScanHeaderOf).
ScanFileStatistics SummarizeScanFileStatistics(const ScanFileHeader& header, const std::vector<Scan>& scans,
                                               const std::vector<E57ImageSummary>& images);

// An E57 photo read whole, recolor_ready left false (recolor/e57_camera.h: SummarizeE57Images sets it).
E57ImageSummary SummarizeE57Image(const E57Image& image, int index);

// One line of what the file holds: "FILE: FORMAT file, N scan(s)[ at S stations], P points, I image(s)"
// (P: the returns with --stats, else the records the headers state).
std::string BriefReport(const ScanFileSummary& summary);
std::string BriefReport(const ScanFileStatistics& summary);

template <>
const StructInfo& InfoOf<E57MetadataSummary>();
template <>
const StructInfo& InfoOf<ScanSummary>();
template <>
const StructInfo& InfoOf<WorldBoundsSummary>();
template <>
const StructInfo& InfoOf<RangeSummary>();
template <>
const StructInfo& InfoOf<IntensitySummary>();
template <>
const StructInfo& InfoOf<GridSummary>();
template <>
const StructInfo& InfoOf<ScanStatisticsSummary>();
template <>
const StructInfo& InfoOf<ScanImageSummary>();
template <>
const StructInfo& InfoOf<E57ImageIntrinsics>();
template <>
const StructInfo& InfoOf<E57ImageSummary>();
template <>
const StructInfo& InfoOf<E57ImagesSummary>();
template <>
const StructInfo& InfoOf<ScanImageStatisticsSummary>();
template <>
const StructInfo& InfoOf<ScanStationSummary>();
template <>
const StructInfo& InfoOf<ScanFileFacts>();
template <>
const StructInfo& InfoOf<ScanFileSummary>();
template <>
const StructInfo& InfoOf<ScanFileStatistics>();

}  // namespace lidarshop
