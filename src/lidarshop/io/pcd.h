// PCD, the Point Cloud Library's format (v0.7): organized clouds (WIDTH x HEIGHT) read as scans, ASCII,
// binary and binary_compressed (LZF, via liblzf) data; written as binary.
//
// Frames: the numbers in a PCD are the points, in the world frame; VIEWPOINT ("tx ty tz qw qx qy qz") is the
// sensor's pose in that frame (PCL's sensor_origin_ and sensor_orientation_; PCL, Open3D and CloudCompare
// do not apply it to the points). Reading keeps both: WorldPointOfCell gives the file's numbers (to float
// precision relative to the scan's origin) and world_from_scanner is the sensor pose:
//   - organized cloud (HEIGHT > 1): a camera image whose sensor frame is PCL's optical frame (x right, y down,
//     z forward), world_from_scanner = VIEWPOINT · camera_from_scanner with (x, y, z)_camera = (x, −z, y)_scanner,
//     so that the image's row 0 is the scan's top row and the ray directions are the sensor's. When more than
//     90 % of the points lie behind that frame (z < 0; PCL's stereo data has VIEWPOINT "0 0 0 0 1 0 0", half
//     a turn about x) the sensor frame is taken as the OpenGL one (y up, z backward): the same position, the
//     image the right way up. Points more than 10 km from the sensor (io_common.h kScanRangeKeptM) are not
//     its rays: they are kept relative to a local origin in the pose, with a warning.
//   - unorganized cloud (HEIGHT = 1): a 1 x N scan in the VIEWPOINT pose, or, when the points lie more than
//     1 km from it, its rotation and a local origin near the points (io_common.h UnorganizedScan; warned).
//     Every point is a return, (0, 0, 0) included.
// lidarshop writes the points in the world frame, VIEWPOINT = the scan's pose (an organized scan's in the
// optical frame, as read) and two header comments:
//   # frame world
//   # lidarshop_scan world_from_scanner <16 numbers, row major>
// The reader takes the pose from the second when present (it is exact), so read(write(scan)) keeps the
// grid, the points and world_from_scanner; VIEWPOINT is what other tools see.
//
// Fields read (names compared without case: PDAL writes FIELDS X Y Z Intensity Red Green Blue): x y z
// (required), rgb/rgba (packed 0xAARRGGBB, TYPE F or U) or red green blue (8- or 16-bit), intensity (integer
// types scaled by their range to [0, 1]), label, normal_x/y/z, synthesized, true_range; other fields are
// skipped. A missing point is NaN, or 0 0 0 in an organized cloud. A file without an `intensity` field gives a
// scan without intensity (Scan::intensity empty), not an invented one. ASCII data may separate values by
// spaces, tabs or commas; its F values are read as doubles (the text's
// precision, whatever SIZE says).
#pragma once

#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// `warnings` (optional) receives what the reader changed to keep precision (a local origin).
Scan ReadPcd(const std::string& path, std::vector<std::string>* warnings = nullptr);
Scan ParsePcd(const std::string& bytes, const std::string& file,
              std::vector<std::string>* warnings = nullptr);

// True when a valid point of `scan` lies more than io_common.h kCloudFloatSafeM (1 km) from the world origin
// in some axis: WritePcd then writes x y z as F 8 (a float there would lose more than 0.06 mm), which some
// readers do not read (Open3D 0.16 reads such coordinates as zeros); PlanScanWrite says so.
bool PcdNeedsDoubleCoordinates(const Scan& scan);

// Binary PCD with x y z (world frame; F 4, or F 8 when PcdNeedsDoubleCoordinates), then each channel the scan
// has: rgb, intensity, label, normal_x/y/z (world frame), curvature, synthesized, true_range; missing returns
// are NaN; VIEWPOINT = the scan's pose and the two comments above. Atomic.
void WritePcd(const std::string& path, const Scan& scan);

}  // namespace lidarshop
