// PCD, the Point Cloud Library's format (v0.7): organized clouds (WIDTH x HEIGHT) read as scans, ASCII,
// binary and binary_compressed (LZF, via liblzf) data; written as binary.
//
// Frames: lidarshop writes every point in the WORLD frame with VIEWPOINT identity, so that tools which
// ignore VIEWPOINT (Open3D, most viewers) see the same coordinates as in lidarshop's PLY, LAS and XYZ. Two
// header comments say what the file holds:
//   # frame world
//   # lidarshop_scan world_from_scanner <16 numbers, row major>
// The reader honours the second: the scan gets that pose back and its points in the scanner frame
// (scanner_from_world · VIEWPOINT · point), so read(write(scan)) keeps the grid, the scanner-frame points and
// world_from_scanner. Without it (PCL, Open3D, older lidarshop files) the file's coordinates are taken in
// the VIEWPOINT frame: an organized cloud (HEIGHT > 1) is a depth-camera image in the optical frame (x right,
// y down, z forward), read as scanner-frame points (x, z, −y) with world_from_scanner = VIEWPOINT ·
// camera_from_scanner; an unorganized cloud (HEIGHT = 1) becomes a 1 x N scan whose points are taken as they
// are (pose = VIEWPOINT). Either way the world coordinates are those of the file.
//
// Fields read: x y z (required), rgb/rgba (packed 0xAARRGGBB, TYPE F or U), intensity, label, normal_x/y/z,
// synthesized, true_range; other fields are skipped. NaN (or 0 0 0) coordinates mark a missing return. A file
// without an `intensity` field gives a scan without intensity (Scan::intensity empty), not an invented one.
#pragma once

#include <string>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

Scan ReadPcd(const std::string& path);
Scan ParsePcd(const std::string& bytes, const std::string& file);

// Binary PCD with x y z (world frame; float, or double when the scanner is over 10 km from the origin), then
// each channel the scan has: rgb, intensity, label, normal_x/y/z (world frame), curvature, synthesized,
// true_range; missing returns are NaN; VIEWPOINT identity and the two comments above. Atomic.
void WritePcd(const std::string& path, const Scan& scan);

}  // namespace lidarshop
