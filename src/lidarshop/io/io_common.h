// Helpers shared by the scan readers and writers (internal to the io module).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop::io_internal {

// Reads a whole regular file (util/input_file.h: FIFOs, devices and folders are refused without opening
// them). Throws InputError naming the file when it cannot be read.
std::string ReadFileToString(const std::string& path);
// The first `max_bytes` bytes of the regular file `path` (all of it when shorter), for header readers.
std::string ReadFilePrefix(const std::string& path, int64_t max_bytes);
// `size` bytes at `offset` of `path`; throws InputError naming `what` when the file is shorter.
std::string ReadFileRange(const std::string& path, int64_t offset, int64_t size, const std::string& what);

// What a reader allocates per cell of a scan: every channel it may fill (point, direction, range, intensity,
// colour, flags) and the grid fit.
constexpr int64_t kScanBytesPerCell = 64;

// Throws InputError naming `file` and `place` when rows x cols is negative, more than kMaxScanCells, or more
// than the memory budget (util/memory_budget.h) holds, before anything is allocated.
void CheckScanSize(int64_t rows, int64_t cols, const std::string& file, const std::string& place);

// A grid that the file's points index (PLY row/col, E57 rowIndex/columnIndex) is bounded by the bytes: a
// few hundred bytes cannot make a reader allocate gigabytes. Throws InputError unless rows x cols is at most
// max(2^22, kCellsPerDataByte x data_bytes) — room for scans that are mostly sky.
constexpr int64_t kCellsPerDataByte = 64;
void CheckGridFromData(int64_t rows, int64_t cols, int64_t data_bytes, const std::string& file,
                       const std::string& place);
// The cells (or records) of everything a file declares together — several grids, records of fields that
// take no bits — against the same bounds as one grid: at most kMaxScanCells, at most
// max(2^22, kCellsPerDataByte x data_bytes), and `cells x bytes_per_cell` within the memory budget. Throws
// InputError naming `file`, `place` and `what` ("cells of all lidarshop_scan comments").
void CheckCellsFromData(int64_t cells, int64_t bytes_per_cell, int64_t data_bytes, const std::string& file,
                        const std::string& place, const std::string& what);

// Checks what a reader produced before any algorithm sees it: the pose is rigid (geometry
// PoseProblem) and every valid point is within kMaxCoordinateM. Throws InputError naming `file`,
// `place`, the cell and the field.
void CheckScanNumbers(const Scan& scan, const std::string& file, const std::string& place);

// After a reader has filled `valid` and `point`: sets range = |point| and direction = point / range of valid
// cells (a valid point at the origin of an unorganized cloud: range 0, direction 0), clears invalid cells (point 0, range 0, intensity 0.5 when present, colour 0) and, when `fit_grid`, fits the
// angular grid so that every cell gets a direction (FitGrid). A scan without any return keeps zero
// directions.
void FinishScan(Scan* scan, bool fit_grid);

// Unorganized clouds in world coordinates (LAS, XYZ) keep their points as float offsets from an origin that
// becomes world_from_scanner's translation: (0, 0, 0) when every coordinate of the bounds [low, high] is within
// kCloudFloatSafeM (float steps of 0.06 mm there), else the centre of the bounds rounded to a metre, so that
// world coordinates keep 0.1 mm over clouds a few kilometres wide.
// With `step_m` (the file's own resolution, e.g. a LAS scale): (0, 0, 0) only when float also keeps that step
// over the bounds, and the centre rounded to a metre, or to `step_m` where a metre is too coarse (a cloud in
// degrees), else — so that a LAS file's integers come back.
constexpr double kCloudFloatSafeM = 1000.0;
Eigen::Vector3d CloudOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high);
Eigen::Vector3d CloudOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high, double step_m);
// The spacing of floats at magnitude `value` (2^-23 of its power of two), metres.
double FloatStepAt(double value);
// Whether every coordinate in [low, high] (relative to the origin) is a float within half of `step_m` of
// its double value.
bool FloatKeepsStep(const Eigen::Vector3d& low, const Eigen::Vector3d& high, double step_m);

// An unorganized point list (XYZ, PTS, a plain PLY cloud, an unorganized PCD; LAS may use it) as a 1 x N scan
// in list order, N = points_in_world.size(). `valid` (empty = every entry) marks the entries that are points
// (a PCD's NaN is not). In an unorganized file the origin is a point like any other: every valid entry becomes
// a return, (0, 0, 0) included ("no return" is a convention of organized grids only).
// The pose: `preferred_pose` (a rigid motion; a PCD's VIEWPOINT, identity elsewhere) when every point lies
// within kCloudFloatSafeM of its position in each axis, else the same rotation with the translation
// CloudOrigin of the points' bounds. Points are float offsets from that origin, so that world coordinates keep
// 0.1 mm also 5,000 km from (0, 0, 0). When a point lies exactly on the origin (it would have no ray) the
// origin moves down (world -z) by a whole number of 2^-10 m steps, the fewest that leave no point on it: every
// valid cell has range > 0 and a direction. Colour (0) and intensity (0.5) are allocated as asked, for the
// caller to fill; range and direction are set (FinishScan, no grid).
Scan UnorganizedScan(const std::vector<Eigen::Vector3d>& points_in_world, const std::vector<uint8_t>& valid,
                     bool with_color, bool with_intensity,
                     const Eigen::Matrix4d& preferred_pose = Eigen::Matrix4d::Identity());

// `origin`, moved down (-z of the points' frame) by the fewest whole 2^-10 m steps that leave none of the
// valid `points` exactly on it (a point there would have no ray); `valid` empty = all.
Eigen::Vector3d OriginClearOfPoints(Eigen::Vector3d origin, const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<uint8_t>& valid);

// Organized scans (PTX, organized PCD) keep their scanner origin while every point lies within
// kScanRangeKeptM of it in each axis (float steps there are at most 1 mm, below any scanner's noise at such
// ranges; under 2 km they are under 0.12 mm). Points farther away are not rays of that scanner (a file of
// georeferenced points with an identity pose): the reader then keeps them relative to a local origin
// (FarScanOrigin) held in the pose and says so in a warning.
constexpr double kScanRangeKeptM = 10000.0;
// (0, 0, 0) when the scanner-frame bounds [low, high] lie within kScanRangeKeptM, else the centre of the
// bounds rounded to a metre (scanner frame).
Eigen::Vector3d FarScanOrigin(const Eigen::Vector3d& low, const Eigen::Vector3d& high);

// The world bounds of `points` (entries with valid[i] == 0 skipped; empty `valid` = all); low > high when
// none is valid.
void PointBounds(const std::vector<Eigen::Vector3d>& points, const std::vector<uint8_t>& valid,
                 Eigen::Vector3d* low, Eigen::Vector3d* high);

// An image as CV_8UC3 RGB (grey and RGBA converted, 16-bit scaled down), for mesh textures.
cv::Mat TextureToRgb8(const cv::Mat& image);

// `value` as an int32 when it is a whole number in range, else `fallback` (no undefined
// float-to-int casts on hostile input).
inline int32_t ToInt32(double value, int32_t fallback = -1) {
  return value >= -2147483648.0 && value <= 2147483647.0 &&
                 value == static_cast<double>(static_cast<int64_t>(value))
             ? static_cast<int32_t>(value)
             : fallback;
}

// Appends the shortest decimal form of `value` that reads back to the same float/double (std::to_chars).
void AppendNumber(std::string* out, float value);
void AppendNumber(std::string* out, double value);
void AppendNumber(std::string* out, int64_t value);

}  // namespace lidarshop::io_internal
