// LAS (ASPRS LIDAR Data Exchange Format), written from the specification (LAS 1.4 R15; no Debian package
// reads it). Points only: a LAS file is an unorganized cloud in world coordinates.
//
// Reading: versions 1.0-1.4, point data record formats 0-10 (4, 5, 9 and 10 are 1, 3, 6 and 8 with waveform
// packet descriptors, which are skipped). The file becomes one 1 x N scan in file order:
//   point       X * scale + offset per axis (double), kept as float relative to an origin that becomes
//               world_from_scanner's translation (io_common.h CloudOrigin): (0, 0, 0) when float keeps the
//               file's step there, else the centre of the bounds, so coordinates come back to the file's
//               step (a warning says when a cloud is too wide for that). Every record is a point, the origin
//               included (it has range 0 and no ray direction).
//   intensity   intensity / 65535 (the specification normalizes intensity to 16 bits) when some point has a
//               non-zero intensity; a file whose intensities are all 0 holds none (LAS: 0 = not recorded),
//               and the scan has no intensity channel
//   color       formats 2, 3, 5, 7, 8, 10: RGB / 257 rounded; files that put 8-bit values in the 16-bit
//               fields (every value <= 255, a common writer mistake) are taken as 8-bit
//   label       the classification value (0-31 in formats 0-5, 0-255 in 6-10) when some point's is non-zero
//   synthesized the "synthetic" bit (255) when some point has it
//   from_station the user data byte, when the file holds lidarshop's record (user ID "lidarshop", record 1:
//               a file lidarshop wrote of scans with cells filled from other stations); otherwise user data
//               is the kLasUserData attribute
//   attributes  (Scan::attributes, each only when some point's value is not 0) every other standard field:
//               kLasGpsTime .. kLasExtraBytes below. The original 16-bit colour is kept in kLasRgb16 when
//               it is not 8-bit colour times 257, so LAS -> LAS keeps it exactly.
// Variable length records (and LAS 1.4's extended ones): the coordinate reference system (LASF_Projection:
// GeoTIFF keys 34735-34737, WKT 2111/2112), the classification lookup and text area (LASF_Spec 0, 3) and the
// extra bytes' description (LASF_Spec 4) are kept in Scan::source_records; others are left out with a
// warning. A count of records that does not fit before the points is read as far as it fits, with a warning.
// The header's scale, offset, point format, GPS time type and file source ID are kept in
// Scan::source_metadata ("las.*"), so that LAS -> LAS writes the same integers.
// LAZ (LASzip-compressed LAS: the point format byte's bits 7-6 and a "laszip encoded" VLR) is read the same
// way: the points are decompressed by io/laz.h (written from the LAZ specification, as no LASzip library is
// packaged for lidarshop's platform: point formats 0-3 and 6-8 with extra bytes, LASzip 1.0-3.x and COPC
// files; wave packets are refused) into the records an uncompressed file holds. Every header field is
// checked against the file size before anything is allocated; errors name the file, the byte offset or
// header (LAZ: the chunk and point), the field and the value. A header that promises more points than the
// file holds is refused (LAZ: more than 4 a compressed byte, or than the chunk table holds); one that
// promises 0 gives a scan of 0 points.
//
// Writing: the valid points of every scan in the world frame (world_from_scanner applied), one record each.
//   coordinates the scale and offset of the source LAS when every scan came from LAS files with the same
//               ones (`keep_source_scale`), else scale `coordinate_scale_m` (default 0.1 mm) and offset =
//               floor of the minimum per axis, so a coordinate is within half a step of its double value; an
//               extent that does not fit int32 steps is refused with the step to use instead
//   intensity   round(clamp(intensity, 0, 1) * 65535); 0 (not recorded) for a scan without intensity
//   colour      R * 257 (255 -> 65535) in formats 2, 3, 7, 8 (kLasRgb16 when present); scans without colour
//               are written black there
//   class       the label clamped to 0..31 (formats 0-3) or 0..255 (6-8); a larger label becomes the largest
//               class, a point without a label (kNoLabel) class 0 ("created, never classified"), which
//               reads back as label 0; scans without labels are written as class 0
//   synthetic   the specification's synthetic flag on every synthesized point (classification bit 5 in
//               formats 0-3, classification flags bit 0 in 6-8): synthesized data is always marked
//   attributes  every kLas* attribute the point format holds; return 1 of 1 and point source ID = the scan's
//               index where a scan has none
//   from_station when some scan has the channel (site/from_stations.h): its value (1 + the index of the
//               station the point was taken from, 0 = not) in the user data byte, which then does not hold the
//               kLasUserData attribute, and lidarshop's record (user ID "lidarshop", record 1) says so
// Point format -1 (the default) = the source's format when every scan came from LAS files of one format
// that holds their attributes, else (1.4) 8 with NIR, 7 with colour, 6 without; (1.2) 3/2 with colour, 1/0.
// VLRs: the scans' source records (the first scan's, when several scans carry different ones), with the
// extra bytes' description only when the records carry those bytes. Header 1.4 (375 bytes) or 1.2 (227);
// formats 6-8 set the global encoding's WKT bit as the specification requires. Atomic.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// Names of the LAS fields kept in Scan::attributes (cv::Mat type in brackets).
inline constexpr const char* kLasGpsTime = "gps_time";                   // CV_64F, seconds
inline constexpr const char* kLasReturnNumber = "return_number";         // CV_8U, 1-15
inline constexpr const char* kLasNumberOfReturns = "number_of_returns";  // CV_8U, 1-15
// CV_8U, LAS 1.4's classification flag bits without the synthetic one: 2 key-point, 4 withheld, 8 overlap.
inline constexpr const char* kLasClassFlags = "classification_flags";
inline constexpr const char* kLasScannerChannel = "scanner_channel";        // CV_8U, 0-3
inline constexpr const char* kLasScanDirection = "scan_direction_flag";     // CV_8U, 0/1
inline constexpr const char* kLasEdgeOfFlightLine = "edge_of_flight_line";  // CV_8U, 0/1
inline constexpr const char* kLasScanAngle = "scan_angle_deg";              // CV_32F, degrees
inline constexpr const char* kLasUserData = "user_data";                    // CV_8U
inline constexpr const char* kLasPointSourceId = "point_source_id";         // CV_16U
inline constexpr const char* kLasNir = "nir";                               // CV_16U
inline constexpr const char* kLasRgb16 = "rgb16";                           // CV_16UC3, R G B
// CV_8UC(n): the n extra bytes after each record, as the LASF_Spec 4 record in source_records describes them.
inline constexpr const char* kLasExtraBytes = "las_extra_bytes";
// lidarshop's variable length record: the user data byte holds Scan::from_station.
inline constexpr const char* kLasLidarshopUserId = "lidarshop";
inline constexpr int kLasFromStationRecordId = 1;

struct LasWriteOptions {
  // LAS 1.x: 4 (LAS 1.4, 375-byte header, formats 0-3 and 6-8) or 2 (LAS 1.2, formats 0-3: for older
  // readers).
  int minor_version = 4;
  // Point data record format: -1 = from the scans (1.4: 7 with colour, 6 without; 1.2: 2 with colour, 0
  // without); else 0 (xyz), 1 (+ GPS time), 2 (+ RGB), 3 (+ GPS time + RGB), 6 (1.4 base, GPS time), 7 (6 +
  // RGB) or 8 (7 + NIR, written 0).
  int point_format = -1;
  // Step of the integer coordinates, metres: 1e-4 keeps every coordinate within 0.05 mm.
  double coordinate_scale_m = 1e-4;
  // Keep the source LAS files' scale and offset (when every scan came from LAS with the same ones and the
  // points fit them): LAS -> LAS writes the same integers.
  bool keep_source_scale = true;
  void Check() const;  // throws OptionsError (formats 6-8 need minor_version 4)
};
template <>
const StructInfo& InfoOf<LasWriteOptions>();

// Reads a LAS file (see above). Throws InputError naming the file, the place and the field.
// The point data record format EncodeLas writes `scans` in (options.point_format, or the rule above for -1).
int ChooseLasPointFormat(const std::vector<Scan>& scans, const LasWriteOptions& options);
// The attributes of Scan::attributes that point format `format` (LAS 1.`minor_version`) cannot hold.
std::vector<std::string> LasAttributesNotHeld(const std::vector<Scan>& scans, int format);

// What the reader could read but not keep comes in `warnings` (one sentence each, naming the file).
Scan ReadLas(const std::string& path, std::vector<std::string>* warnings = nullptr);
Scan ParseLas(const std::string& bytes, const std::string& file,
              std::vector<std::string>* warnings = nullptr);

// Writes the valid points of `scans` (see above). Throws InputError naming `path` when no scan has a valid
// point or the extent does not fit the coordinate step. Atomic.
void WriteLas(const std::string& path, const std::vector<Scan>& scans, const LasWriteOptions& options = {});
// The bytes WriteLas writes; `file` names the output in errors.
std::string EncodeLas(const std::vector<Scan>& scans, const LasWriteOptions& options,
                      const std::string& file);

// The coordinate reference system that `records` (Scan::source_records) describe, for `info`: {"wkt": ...}
// from an OGC WKT record, {"geotiff": {"projected_epsg", "geographic_epsg", "vertical_epsg",
// "linear_units_code", "citation", "keys"}} from GeoTIFF keys (each only when present); {} without either.
nlohmann::ordered_json LasCrsJson(const std::vector<SourceRecord>& records);

// The message of the InputError for writing a .laz file ("LAZ is not written: ... write .las instead").
std::string LazNotWrittenMessage();

}  // namespace lidarshop
