// ASCII point lists: XYZ (`.xyz`) and Leica PTS (`.pts`), one point per line, world coordinates:
//
//   x y z [intensity] [r g b]      3, 4, 6 or 7 numbers, separated by blanks (the first data line decides;
//                                  every line must have as many)
//
// PTS starts with a line holding the number of points that follow; several such blocks may follow each other
// (Leica writes one per scan) and are read as one cloud. A count line is a line holding one whole number;
// every other line is a point. A count that is missing (points from the first line) or wrong (more or fewer
// points follow it than it says) does not stop the reading: every point line is read and ScanFile::warnings
// says which count disagreed; a line that is neither a count nor a point of the first point line's columns
// is refused, naming the line and the reason. Lines starting with '#' or '//' are comments (XYZ only);
// empty lines are skipped.
//
// Reading gives one 1 x N scan in file order (io_common.h UnorganizedScan): points kept as float offsets from
// an origin held in double precision in world_from_scanner ((0, 0, 0) for clouds within 1 km, else the
// centre of the bounds rounded to a metre, so UTM coordinates keep 0.1 mm). Every line is a point, (0, 0, 0)
// included: "no return" is a convention of organized grids, not of point lists. Intensity: PTS uses Leica's
// integer range -2048..2047, read as (i + 2048) / 4095 (a PTS file with values outside that range is read as
// XYZ); XYZ intensities are kept when all lie in [0, 1], else mapped linearly from [min(0, lowest),
// max(1, highest)] to [0, 1] (0-255 files become i / 255). Without an intensity column the scan has no
// intensity channel. Colour is 0-255 per channel. Errors name the file, the line and the column.
//
// Reading keeps the finest step the file prints (its first 64 KiB) in Scan::source_metadata["text.step_m"].
// Writing: the valid points of every scan in the world frame, 5 decimals (0.01 mm) or as many as the
// source's step needs (text.step_m, a LAS scale; at most 12), then, when a scan has
// intensity, the intensity (XYZ: the shortest decimal that reads back to the same float; PTS:
// round(i * 4095) - 2048; 0.5 for a scan without among scans with) and, when a scan has
// colour, r g b (0 0 0 for a scan without). These formats cannot mark synthesized points: they are written
// like measured ones, and PlanScanWrite (io/scan_write_plan.h) says so, so that `convert` warns and can leave
// them out (--drop-synthesized) or record them (--synthesized-mask). Atomic.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

enum class PointListKind { kXyz, kPts };

// `warnings` (optional) receives what the reader read despite the file (a PTS count line missing or wrong).
Scan ReadPointList(const std::string& path, PointListKind kind, std::vector<std::string>* warnings = nullptr);
Scan ParsePointList(const std::string& bytes, const std::string& file, PointListKind kind,
                    std::vector<std::string>* warnings = nullptr);

void WritePointList(const std::string& path, const std::vector<Scan>& scans, PointListKind kind);

}  // namespace lidarshop
