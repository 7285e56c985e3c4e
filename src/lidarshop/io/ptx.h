// PTX, Leica's ASCII scan format: one or several organized scans after each other in one file.
//
// Each scan is a header of 10 lines, then columns x rows point lines:
//   line 1      columns                       (number of vertical strips)
//   line 2      rows                          (points per strip)
//   line 3      scanner position              x y z (registered, world frame)
//   lines 4-6   scanner axes                  the world directions of the scanner's x, y and z axes
//   lines 7-10  4 x 4 matrix, as Leica prints it: the TRANSPOSE of world_from_scanner, i.e. the first
//               three printed rows hold the rotation's columns followed by 0, the fourth printed row is
//               "tx ty tz 1".
//               (A file that prints the usual layout, translation in the 4th column and "0 0 0 1" last, is
//               recognised by that last row and read as printed.)
//   points      "x y z intensity" or "x y z intensity r g b", scanner frame, metres, intensity as printed
//               (usually [0, 1]), colour 0-255; column-major: each column a vertical strip listed bottom to
//               top, columns left to right. PTX row r (counted from the bottom) is image row rows - 1 - r.
// The pose is always a rigid motion: a transform A that is not exactly orthonormal (a rotation printed to 6
// decimals) or that scales the scanner's axes (A = R · diag(sx, sy, sz), each scale in [1e-3, 1e3]; PDAL
// applies the whole matrix to the points) gives the pose R (polar decomposition A = R · S) and the points
// S · p, so the world coordinates are the transform's; a scale beyond rounding is said in a warning. A shear,
// a mirror or a singular matrix is refused (InputError, field 'pose'). Points are parsed as doubles; when
// they lie more than 10 km (io_common.h kScanRangeKeptM) from the scanner origin (a file of georeferenced
// points with an identity transform, as PDAL writes them) they are not that scanner's rays: they are kept
// relative to a local origin near them, held in the pose's position, with a warning, so that world
// coordinates keep the file's precision.
// A no-return cell is "0 0 0 0.5" (colour "0 0 0"); reading x = y = z = 0 marks the cell invalid.
//
// Readers accept 4- and 7-field lines (a 7-field line in a 4-field scan adds a colour channel), CRLF endings
// and blank lines, and reject anything else with an InputError naming the file, the line and the field. The
// header is checked against kMaxScanCells before any allocation.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct PtxReadOptions {
  // Fit the angular grid (FitGrid) so that every cell, also without a return, gets a direction. Off only for
  // benchmarks of the parser itself.
  bool fit_grid = true;
};
template <>
const StructInfo& InfoOf<PtxReadOptions>();

// Reads every scan of a PTX file; `warnings` (optional) receives what the reader changed (a scale applied, a
// local origin chosen), one sentence each starting with the file's path.
std::vector<Scan> ReadPtx(const std::string& path, const PtxReadOptions& options = {},
                          std::vector<std::string>* warnings = nullptr);

// Parses PTX text held in memory; `file` names it in error messages.
std::vector<Scan> ParsePtx(std::string_view text, const std::string& file, const PtxReadOptions& options = {},
                           std::vector<std::string>* warnings = nullptr);

// The PTX text of `scans` (floats printed in their shortest round-trip form). Colour lines have 7 fields when
// the scan has colour.
std::string FormatPtx(const std::vector<Scan>& scans);

// Writes `scans` to `path` atomically.
void WritePtx(const std::string& path, const std::vector<Scan>& scans);

}  // namespace lidarshop
