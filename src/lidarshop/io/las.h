// LAS (ASPRS LIDAR Data Exchange Format), written from the specification (LAS 1.4 R15; no Debian package
// reads it). Points only: a LAS file is an unorganized cloud in world coordinates.
//
// Reading: versions 1.0-1.4, point data record formats 0-10 (4, 5, 9 and 10 are 1, 3, 6 and 8 with waveform
// packet descriptors, which are skipped, as are extra bytes after a record). The file becomes one 1 x N scan in file order:
//   point       X * scale + offset per axis (double), kept as float relative to an origin that becomes
//               world_from_scanner's translation: (0, 0, 0) when every coordinate is within 1 km, else the
//               centre of the points' bounds rounded to a metre, so world coordinates keep 0.1 mm (float
//               precision at 1 km is 0.06 mm). A point exactly at that origin has no ray and is left out,
//               as in PLY and PCD.
//   intensity   intensity / 65535 (the specification normalizes intensity to 16 bits) when some point has a
//               non-zero intensity; a file whose intensities are all 0 holds none (LAS: 0 = not recorded),
//               and the scan has no intensity channel
//   color       formats 2, 3, 7, 8: RGB / 257 rounded; files that put 8-bit values in the 16-bit fields (every
//               value <= 255, a common writer mistake) are taken as 8-bit
//   label       the classification value (0-31 in formats 0-3, 0-255 in 6-8) when some point's is non-zero
//   synthesized the "synthetic" bit (255) when some point has it
// GPS time, return numbers, scan angle, user data, point source ID, NIR and VLRs are not kept.
// LAZ (LASzip-compressed LAS: the point format byte's bits 7-6 and a "laszip encoded" VLR) is read the same
// way: the points are decompressed by io/laz.h (written from the LAZ specification, as no LASzip library is
// packaged for lidarshop's platform: point formats 0-3 and 6-8 with extra bytes, LASzip 1.0-3.x and COPC
// files; wave packets are refused) into the records an uncompressed file holds. Every header field is
// checked against the file size before anything is allocated; errors name the file, the byte offset or
// header (LAZ: the chunk and point), the field and the value.
//
// Writing: the valid points of every scan in the world frame (world_from_scanner applied), one record each,
// point source ID = the scan's index in the file; return 1 of 1; GPS time 0 (scans have no time channel).
//   coordinates scale `coordinate_scale_m` (default 0.1 mm), offset = floor of the minimum per axis, so a
//               coordinate is within half a step of its double value; an extent that does not fit int32
//               steps is refused with the step to use instead
//   intensity   round(clamp(intensity, 0, 1) * 65535); 0 (not recorded) for a scan without intensity
//   colour      R * 257 (255 -> 65535) in formats 2, 3, 7, 8; scans without colour are written black there
//   class       the label clamped to 0..31 (formats 0-3) or 0..255 (6-8); a larger label becomes the largest
//               class, a point without a label (kNoLabel) class 0 ("created, never classified"), which
//               reads back as label 0; scans without labels are written as class 0
//   synthetic   the specification's synthetic flag on every synthesized point (classification bit 5 in
//               formats 0-3, classification flags bit 0 in 6-8): synthesized data is always marked
// Header 1.4 (375 bytes) or 1.2 (227 bytes), no VLRs (no coordinate reference system is known); formats 6-8
// set the global encoding's WKT bit as the specification requires. Atomic.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

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
  void Check() const;  // throws OptionsError (formats 6-8 need minor_version 4)
};
template <>
const StructInfo& InfoOf<LasWriteOptions>();

// Reads a LAS file (see above). Throws InputError naming the file, the place and the field.
Scan ReadLas(const std::string& path);
Scan ParseLas(const std::string& bytes, const std::string& file);

// Writes the valid points of `scans` (see above). Throws InputError naming `path` when no scan has a valid
// point or the extent does not fit the coordinate step. Atomic.
void WriteLas(const std::string& path, const std::vector<Scan>& scans, const LasWriteOptions& options = {});
// The bytes WriteLas writes; `file` names the output in errors.
std::string EncodeLas(const std::vector<Scan>& scans, const LasWriteOptions& options,
                      const std::string& file);

// The message of the InputError for writing a .laz file ("LAZ is not written: ... write .las instead").
std::string LazNotWrittenMessage();

}  // namespace lidarshop
