// PCD, the Point Cloud Library's format (v0.7): organized clouds (WIDTH x HEIGHT) read as scans, ASCII,
// binary and binary_compressed (LZF, via liblzf) data; written as binary.
//
// Frames: an organized PCD cloud (HEIGHT > 1) is a depth-camera image in the optical frame (x right, y down,
// z forward); its row r is image row r. lidarshop's scanner frame is x right, y forward, z up, so a point is
// read as (x, z, -y) and world_from_scanner = viewpoint * camera_from_scanner, which keeps the cloud's world
// coordinates. Writing does the inverse, so a scan survives the round trip. An unorganized cloud (HEIGHT = 1)
// becomes a 1 x N scan whose points are taken as they are (pose = VIEWPOINT).
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

// Binary PCD with x y z, then each channel the scan has: rgb, intensity, label, normal_x/y/z, synthesized,
// true_range; missing returns are NaN. Atomic.
void WritePcd(const std::string& path, const Scan& scan);

}  // namespace lidarshop
