// The ray direction of every cell of a scan, whether the scan holds them as an image or as its angular grid.
//
// A station's rays are those of its grid (an azimuth per column, an elevation per row) wherever the scanner kept
// to it, and an image of them costs 12 bytes a ray: a third of a station read with intensity and colour
// (docs/memory.md). So `Scan::direction` may be empty when the scan's grid is complete (an entry per column
// and per row): every cell's direction is then its grid direction, DirectionFromAngles(azimuth[col],
// elevation[row]). ReadE57 leaves it empty when the file's rays are the grid's bit for bit. Code that reads
// directions asks this header, never `scan.direction` itself.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// True when the grid has an azimuth per column and an elevation per row.
bool HasCompleteGrid(const Scan& scan);
// True when the scan knows its rays: it holds `direction`, or its grid is complete.
bool HasRayDirections(const Scan& scan);

// The directions as an image (CV_32FC3, rows x cols): `scan.direction` itself (shared) when held, else
// DirectionsFromGrid(scan.grid), a new image of 12 bytes a ray; empty when the scan knows no rays. For code
// that works on a window of a station (CropScan keeps the window's grid) or on every ray at once.
cv::Mat DirectionImage(const Scan& scan);

// One cell's direction without an image: the held one, or the grid's from tables of the angles' sines and
// cosines (the same doubles as DirectionFromAngles, so the same floats as DirectionsFromGrid).
class RayDirections {
 public:
  // Throws std::logic_error when the scan knows no rays (HasRayDirections false). Keeps a view of
  // `scan.direction` when held; the scan's grid is copied into tables.
  explicit RayDirections(const Scan& scan);
  // The rays of `grid` alone (its azimuths are the columns, its elevations the rows).
  explicit RayDirections(const ScanGrid& grid);
  cv::Vec3f operator()(int row, int col) const {
    if (!image_.empty()) return image_.at<cv::Vec3f>(row, col);
    return cv::Vec3f(static_cast<float>(cos_elevation_[row] * sin_azimuth_[col]),
                     static_cast<float>(cos_elevation_[row] * cos_azimuth_[col]), sin_elevation_[row]);
  }
  cv::Vec3f At(int64_t cell) const {
    return (*this)(static_cast<int>(cell / cols_), static_cast<int>(cell % cols_));
  }
  bool from_grid() const { return image_.empty(); }

 private:
  cv::Mat image_;
  int cols_ = 0;
  std::vector<double> sin_azimuth_, cos_azimuth_, cos_elevation_;
  std::vector<float> sin_elevation_;
};

// Releases `scan->direction` when the grid is complete and every cell's held direction is its grid direction
// bit for bit; returns whether it did. Directions that differ anywhere are kept whole.
bool ReleaseGridDirections(Scan* scan);

// How the valid points' directions sit around their cells' rays under `grid` (complete for the scan): FitGrid's
// residual, and for a grid a file stored, whether it is this scan's at all.
struct GridResidual {
  double rms_rad = 0.0;  // RMS angle between a point's direction and its cell's ray
  double max_rad = 0.0;
  // Mean signed offsets of the points from their rays, along the ray's local east (azimuth rising) and north
  // (elevation rising) directions, radians: noise averages out, a grid shifted by a step does not.
  double mean_east_rad = 0.0;
  double mean_north_rad = 0.0;
};
GridResidual MeasureGridResidual(const Scan& scan, const ScanGrid& grid);

// MakeScan without the direction image: for a reader that sets the grid itself (the scan is not valid for
// CheckScan's callers until its grid is complete or a direction image is set).
Scan MakeScanWithoutDirections(int rows, int cols, bool with_color, bool with_intensity);

}  // namespace lidarshop
