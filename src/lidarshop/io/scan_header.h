// What a scan file says about itself without reading its points: the E57 XML section, the PTX scan headers,
// the PLY / PCD / LAS headers. `lidarshop info` prints it (scan_summary.h: its --stats reads the points as
// well), the server and the Python module can ask it before deciding to load a file.
//
// Per format, what comes from where (nothing else is read):
//   .e57  the 48-byte file header and the XML section (its pages' CRCs checked): data3D entries (name, guid,
//         sensor, acquisition dates, pose, recordCount, indexBounds for rows x cols, the prototype's fields
//         as channels), images2D entries (name, size, kind, the scan they belong to) and the root's guid.
//         An organized scan whose XML has no indexBounds has rows = cols = -1 (unknown without the points).
//   .ptx  each scan's 10 header lines (columns, rows, pose) and its first point line (4 or 7 fields: colour);
//         the point lines are skipped, not parsed, to find the next scan.
//   .ply  the header up to end_header: the vertex count, the properties (channels), lidarshop's
//         "lidarshop_scan" comments (grid and pose of each scan).
//   .pcd  the header up to DATA: FIELDS (channels), WIDTH x HEIGHT, VIEWPOINT (pose as the reader makes it).
//   .las  the public header block and the VLRs: point count, point format (colour), bounds, scale, offset,
//         points by return, the records and the coordinate reference system.
//   .xyz .pts  no header: the whole file is read (as ReadScanFile does).
// Channels are named as ChannelNames (scan/scan.h) names them; a channel is listed only when the header
// declares it ("intensity" only with a PCD/PLY intensity field, an E57 prototype's intensity, a PTX file (its
// fourth column) or a LAS file (every LAS point format has one)). Values decide a few channels the full
// reader adds (a LAS file whose classes are all 0 has no labels once read): the header lists what the file
// can hold.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// Sensor and acquisition facts of an E57 data3D or images2D entry; empty strings where the file says nothing.
struct E57Metadata {
  std::string guid;
  std::string description;
  std::string sensor_vendor, sensor_model, sensor_serial_number;
  std::string sensor_hardware_version, sensor_software_version, sensor_firmware_version;
  // Acquisition times as the file stores them (GPS seconds since 1980-01-06 00:00 UTC) and as UTC text
  // ("2011-06-14T16:07:02Z", leap seconds applied); NaN / "" when absent.
  double acquisition_start_gps_s = std::numeric_limits<double>::quiet_NaN();
  double acquisition_end_gps_s = std::numeric_limits<double>::quiet_NaN();
  std::string acquisition_start_utc, acquisition_end_utc;
};

// One variable length record of a LAS file, as `lasinfo` lists it.
struct LasRecordSummary {
  std::string user_id;
  int record_id = 0;
  std::string description;
  int64_t bytes = 0;  // the payload's length
};

// The bounds a LAS header states, metres in the file's coordinates.
struct LasBoundsSummary {
  std::vector<double> min, max;  // x, y, z
};

// A LAS file's public header block and VLRs as `pdal info` / `lasinfo` show them.
struct LasHeaderSummary {
  std::string version;  // "1.4"
  int point_format = 0;
  int record_length = 0;              // bytes per point record
  int extra_bytes = 0;                // record_length beyond the point format's own fields
  std::vector<double> scale, offset;  // x, y, z: coordinate = offset + scale x stored integer
  LasBoundsSummary bounds;
  std::vector<uint64_t> points_by_return;  // 5 counts (15 for LAS 1.4 with 64-bit counts)
  std::string gps_time;                    // "standard" or "week" for point formats with a GPS time; else ""
  int file_source_id = 0;
  std::vector<LasRecordSummary> vlrs;
  // The coordinate reference system (LasCrsJson: wkt and / or geotiff keys, in the file's order; {} without).
  nlohmann::ordered_json crs;
};

// One scan of a file as its header describes it.
struct ScanHeader {
  std::string name;        // E57 data3D name, else ""
  bool organized = false;  // a grid of rays (PTX, E57 rowIndex/columnIndex, lidarshop PLY, PCD HEIGHT > 1)
  int64_t rows = -1, cols = -1;  // the grid (an unorganized cloud: 1 x points); -1 when unknown
  int64_t points = -1;           // records the file stores for this scan (rows x cols for PTX and organized
                                 // PCD, E57 recordCount, LAS/PLY point count); -1 when unknown
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  std::vector<std::string> channels;    // as ChannelNames names them
  std::string coordinates;              // E57: "cartesian" or "spherical"; else ""
  E57Metadata e57;                      // E57 only
  std::optional<LasHeaderSummary> las;  // LAS only
};

// One images2D entry of an E57 file.
struct ScanImageHeader {
  std::string name;
  std::string projection;  // "pinhole", "spherical", "cylindrical" or "visual"
  std::string encoding;    // "jpeg" or "png"
  int width_px = 0, height_px = 0;
  int64_t encoded_bytes = 0;  // the blob's length
  int scan_index = -1;        // the data3D entry whose guid associatedData3DGuid names; -1 when none
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
  E57Metadata e57;
};

struct ScanFileHeader {
  std::string path;
  std::string format;  // "ptx", "e57", "ply", "pcd", "las", "xyz", "pts"
  int64_t file_size_bytes = 0;
  std::string format_version;  // "E57 1.0", "PCD 0.7", "LAS 1.4 point format 7", "PLY binary_little_endian"
  std::string guid;            // E57 root guid
  std::string creation_utc;    // E57 creationDateTime as UTC text, "" when absent
  std::vector<ScanHeader> scans;
  std::vector<ScanImageHeader> images;  // E57 images2D
  std::vector<std::string> warnings;    // as ScanFile::warnings
};

// Reads what `path` says about itself (see the table above), chosen by extension. Throws InputError naming
// the file, the place and the field when the header is malformed or truncated, as the full reader would.
ScanFileHeader ReadScanHeader(const std::string& path);

// The header of scans already read (what ReadScanFile gives), for formats without a header and for tests:
// rows, cols, points = cells, channels = ChannelNames.
ScanHeader ScanHeaderOf(const Scan& scan);

// What reading every point of a scan adds to its header (`lidarshop info --stats`): the returns, their bounds
// and range / intensity statistics, LAS counts as `lasinfo` gives them, and the angular grid. Every statistic
// is over the valid cells.
struct ScanStatistics {
  int64_t valid = 0;  // returns (valid cells)
  // Bounds of the returns in the world frame (world_from_scanner applied), metres; empty without returns.
  Eigen::AlignedBox3d bounds_in_world;
  double min_range_m = 0, max_range_m = 0, mean_range_m = 0;  // of the returns; 0 without returns
  // Of the returns, in Scan::intensity's scale; only when the scan has an intensity channel and returns.
  std::optional<double> min_intensity, max_intensity;
  // Scans read from LAS (source_metadata "las.point_format"): returns per classification (Scan::label, 0
  // without one) and per return number (the attribute kLasReturnNumber, 0 without one), ascending.
  bool from_las = false;
  std::map<int, int64_t> returns_by_class, returns_by_return_number;
  // The angular grid (Scan::grid), in degrees: the extreme azimuth and elevation of its columns and rows and
  // the mean step between neighbours; only when the grid's directions are known (steps: with 2 columns /
  // rows or more).
  std::optional<double> min_azimuth_deg, max_azimuth_deg, min_elevation_deg, max_elevation_deg;
  std::optional<double> azimuth_step_deg, elevation_step_deg;
};

// The statistics of `scan` (one pass over its cells).
ScanStatistics ComputeScanStatistics(const Scan& scan);

// The header as `lidarshop info` writes it: ToJson(SummarizeScanFile(header)) (io/scan_summary.h: keys in
// reading order, numbers rounded as people read them).
nlohmann::ordered_json ToJson(const ScanFileHeader& header);

// A 4 x 4 pose (world_from_scanner, world_from_model, ...) as four JSON rows, every entry rounded to 1e-9 (a
// nanometre: it also drops a rotation's 1e-17 noise, so 1.0000000000000002 prints as 1).
nlohmann::ordered_json MatrixJson(const Eigen::Matrix4d& matrix);

// GPS seconds (since 1980-01-06T00:00:00Z, no leap seconds) as UTC text "YYYY-MM-DDThh:mm:ssZ"
// (fractions of a second dropped), leap seconds up to 2017 applied; "" when not finite or before 1980.
std::string UtcFromGpsSeconds(double gps_seconds);

template <>
const StructInfo& InfoOf<LasRecordSummary>();
template <>
const StructInfo& InfoOf<LasBoundsSummary>();
template <>
const StructInfo& InfoOf<LasHeaderSummary>();

namespace io_internal {
// The per-format header readers behind ReadScanHeader (each in its format's .cc).
std::vector<ScanHeader> ReadPtxHeaders(const std::string& path);
ScanFileHeader ReadE57Header(const std::string& path);
ScanFileHeader ReadPlyScanHeader(const std::string& path);
ScanFileHeader ReadPcdHeader(const std::string& path);
ScanFileHeader ReadLasHeader(const std::string& path);
}  // namespace io_internal

}  // namespace lidarshop
