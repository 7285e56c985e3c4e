// The organized scan: a rows x cols grid of laser rays from one scanner origin.
//
// Every channel is an image of the scan's shape, stored in *image orientation*: column = scan column (azimuth
// increasing to the right), row 0 = the top row (highest elevation). A PTX/E57 row r counted bottom to top is
// image row `rows - 1 - r`. Rendered pictures, label images, masks and user strokes all use this orientation.
//
// Scanner frame (the Leica HDS3000 model of the original work): z up, y forward, x right. Azimuth θ is
// measured from +y, positive to the right (θ = +π/2 is +x); elevation φ is positive up. Direction(θ, φ) =
// (cos φ sin θ, cos φ cos θ, sin φ).
//
// Channels (cv::Mat, each rows x cols):
//   direction   CV_32FC3  unit ray of every cell, or EMPTY: the rays are the grid's (read them via ray_directions.h)
//   valid       CV_8U     255 = the ray returned, 0 = no return
//   range       CV_32F    metres from the scanner origin to the point; 0 where invalid
//   point       CV_32FC3  x y z in the scanner frame, metres; 0 where invalid
// Optional channels (empty when absent: a channel the file does not hold is never invented):
//   intensity   CV_32F    return strength in [0, 1] (PTX convention); 0.5 where invalid; empty when the source
//                         holds no intensity (a PCD without an `intensity` field, an E57 without intensity)
//   color       CV_8UC3   R G B (RGB order, not OpenCV's BGR); empty when the scan has no colour
//   label       CV_32S    object label (synthetic scans); kNoLabel where invalid
//   normal      CV_32FC3  unit surface normal in the scanner frame (true normals of synthetic scans)
//   curvature   CV_32F    surface variation λ0 / (λ0 + λ1 + λ2) in [0, 1/3] of the neighbourhood the normal
//                         came from (pointset/normals.h); NaN where invalid or unknown
//   true_range  CV_32F    noise-free range (synthetic scans), 0 where invalid
//   synthesized CV_8U     255 = created by lidarshop (e.g. hole filling), 0 = measured
//   from_station CV_8U    1 + k = a hole cell filled with what another station (k of the list it was given)
//                         measured, resampled onto this scan's ray (site/from_stations.h); 0 = this scan's own
//                         measurement or synthesized. Such a cell is measured, not synthesized.
// Carried, not interpreted (`attributes`): per-cell values of the source file that no algorithm of lidarshop
// uses but that a user expects back (LAS GPS time, return numbers, scan angle, point source ID, NIR, extra
// bytes; io/las.h names them). Each is a rows x cols cv::Mat of 1 to 512 channels of any depth, 0 in cells
// without a return and where the file held 0; a file that holds 0 everywhere has no such attribute. Clone and
// MaskScan keep them; writers that hold an attribute write it, the others say they drop it
// (io/scan_write_plan.h). `source_records` keeps file-level records the same way (LAS VLRs of the coordinate
// reference system), `source_metadata` the source's own settings a writer of the same format reuses.
//
// For a valid cell the measured point need not lie exactly on `direction` (orthogonal noise, real scanners);
// the cell's direction is the nominal grid direction, the point's own direction is point / range.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/geometry/mesh.h"

namespace lidarshop {

constexpr int32_t kNoLabel = -1;
constexpr uint8_t kValid = 255;

// Direction(θ, φ) of the scanner frame, angles in radians.
inline Eigen::Vector3f DirectionFromAngles(double azimuth_rad, double elevation_rad) {
  return Eigen::Vector3d(std::cos(elevation_rad) * std::sin(azimuth_rad),
                         std::cos(elevation_rad) * std::cos(azimuth_rad), std::sin(elevation_rad))
      .cast<float>();
}
// θ = atan2(x, y) in [-π, π]; φ = asin(z / |d|).
double AzimuthOf(const Eigen::Vector3f& direction);
double ElevationOf(const Eigen::Vector3f& direction);
// The angle plus a whole number of turns that lies in [-π, π), radians.
double WrapAngle(double angle_rad);

// The angular grid of a scan: one azimuth per column and one elevation per image row (row 0 = top = highest).
struct ScanGrid {
  std::vector<double> azimuth_rad;    // #cols, increasing to the right
  std::vector<double> elevation_rad;  // #rows, decreasing downwards (image order)
  // How well the grid explains the measured directions (fitted grids): RMS and max angle between a valid
  // point's direction and its cell's grid direction, radians. 0 for exact (synthetic) grids.
  double rms_residual_rad = 0.0;
  double max_residual_rad = 0.0;
  bool fitted = false;  // true when estimated from measured points (FitGrid), false when nominal
};

// A record of the source file kept for writers of the same format: LAS variable length records (`format`
// "las", user ID, record ID, description, payload bytes).
struct SourceRecord {
  std::string format;
  std::string user_id;
  int record_id = 0;
  std::string description;
  std::string payload;
  friend bool operator==(const SourceRecord&, const SourceRecord&) = default;
};

struct Scan {
  int rows = 0;
  int cols = 0;
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  std::string name;  // optional, e.g. the E57 scan name

  cv::Mat direction;
  cv::Mat valid;
  cv::Mat range;
  cv::Mat point;
  cv::Mat intensity;
  cv::Mat color;

  cv::Mat label;
  cv::Mat normal;
  cv::Mat curvature;
  cv::Mat true_range;
  cv::Mat synthesized;
  cv::Mat from_station;

  ScanGrid grid;  // empty vectors when the scan has no known grid

  std::map<std::string, cv::Mat> attributes;           // see the top of this file
  std::vector<SourceRecord> source_records;            // e.g. the CRS VLRs of a LAS file
  std::map<std::string, std::string> source_metadata;  // e.g. "las.point_format" = "3"

  bool has_color() const { return !color.empty(); }
  bool has_intensity() const { return !intensity.empty(); }
  int64_t num_cells() const { return static_cast<int64_t>(rows) * cols; }
  int64_t CountValid() const;
};

// The scan's angular grid: `scan.grid` when it has an entry per column and row, else read off the ray
// directions (a column's azimuth from the cell with a direction nearest the middle row, a row's elevation
// from the cell nearest the middle column; fitted = false). Throws InputError naming the scan and the column
// or row that has no ray direction at all.
ScanGrid GridOf(const Scan& scan);

// Copying a Scan shares the pixel buffers (cv::Mat semantics); Clone() copies every channel. A function that
// changes a channel of a scan it was given must clone first: inputs are never modified.
Scan Clone(const Scan& scan);

// The scan with only the cells where `keep_mask` (CV_8U, rows x cols, non-zero = keep) is set: every other
// cell becomes a cell without a return (valid 0, range 0, point 0, intensity 0.5, colour 0, label kNoLabel,
// normal 0, curvature NaN, true_range 0, synthesized 0, from_station 0, attributes 0) but keeps its direction; grid, pose and name are kept. Used to write
// a cut-out object or the rest of a scan as an organized scan. Throws std::logic_error when the mask has the
// wrong size or type.
Scan MaskScan(const Scan& scan, const cv::Mat& keep_mask);

// The cells of `window` (inside the scan) as a scan of their own: every channel's cells copied, the grid's
// azimuths and elevations of those columns and rows, pose, name and metadata kept. An edit works on the window
// around what it changes (fill: a band around the hole) so that its cost follows the edit, not the scan.
// Throws std::logic_error when `window` is not inside the scan.
Scan CropScan(const Scan& scan, const cv::Rect& window);

// Writes the cells of `part` into `scan` at `window` (the inverse of CropScan): every channel `part` has; a
// channel only `part` has is added to `scan` with the no-return value of MaskScan outside the window. Throws
// std::logic_error when the sizes differ or `window` is not inside the scan.
void PasteScan(const Scan& part, const cv::Rect& window, Scan* scan);

// PasteScan for a scan whose buffers others share (a shallow copy of a scan kept for undo): a channel whose
// window already holds `part`'s values stays shared; any other is copied before it is written (copy on
// write per channel). A fill leaves the ray directions as they were, so the filled station shares them: a
// third of a station's bytes not copied. Never writes into a buffer it found in `scan`.
void PasteScanCopyOnWrite(const Scan& part, const cv::Rect& window, Scan* scan);

// A scan with every required channel allocated (no returns, directions zero), intensity (0.5 everywhere) unless
// `with_intensity` is false, colour (0) when `with_color`, no other optional channel.
Scan MakeScan(int rows, int cols, bool with_color = false, bool with_intensity = true);

// Throws std::logic_error when a channel has the wrong size or type (programming error, not input error).
void CheckScan(const Scan& scan);

// Names of the channels present, e.g. {"xyz", "range", "intensity", "valid", "direction", "rgb", "label"};
// "intensity" only when the scan has it.
std::vector<std::string> ChannelNames(const Scan& scan);

// Directions for every cell from a regular grid (azimuth per column, elevation per image row).
cv::Mat DirectionsFromGrid(const ScanGrid& grid);

// A uniform grid: azimuth from min to max over `cols`, elevation from min (bottom) to max (top) over `rows`,
// steps (max - min) / (N - 1).
ScanGrid UniformGrid(int rows, int cols, double azimuth_min_rad, double azimuth_max_rad,
                     double elevation_min_rad, double elevation_max_rad);

// For real scans: fits per-column azimuth and per-row elevation to the valid points' directions (robust to
// noise: a median per column/row, then a monotone cleanup; columns or rows without any return are
// interpolated from their neighbours or extrapolated with the median step), fills `direction` of every cell
// from the fitted grid and stores the grid and its residual in scan->grid. Valid cells keep their points.
void FitGrid(Scan* scan);

// The point of one cell in the world frame, in double precision (world_from_scanner applied to the float
// point): what writers of world coordinates and correspondences by cell need.
inline Eigen::Vector3d WorldPointOfCell(const Scan& scan, int row, int col) {
  const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
  return scan.world_from_scanner.topLeftCorner<3, 3>() * Eigen::Vector3d(p[0], p[1], p[2]) +
         scan.world_from_scanner.topRightCorner<3, 1>();
}

// Points with all per-point channels, valid cells only, in the scanner frame or (world = true) the world
// frame. `cell_index` (optional) receives row * cols + col of each point.
PointCloud ToPointCloud(const Scan& scan, bool world = false, std::vector<int64_t>* cell_index = nullptr);

// Image views. All CV_32F unless stated; invalid cells are 0 (range) or NaN where said.
cv::Mat RangeImage(const Scan& scan);  // CV_32F metres
cv::Mat DepthImage(const Scan& scan);  // CV_32F, y in the scanner frame (forward distance)
cv::Mat RgbdImage(const Scan& scan);   // CV_32FC4: R, G, B in [0,1] (grey intensity without colour, 0
                                       // without either), range in metres
cv::Mat ValidMask(const Scan& scan);   // CV_8U 255/0 (a copy of scan.valid)

// The label image of the file convention (`--labels L.png`): CV_16U, pixel = the object's label,
// kNoReturnLabel16 where the ray returned nothing or the cell has no label. Throws std::logic_error when the
// scan has no labels.
constexpr uint16_t kNoReturnLabel16 = 65535;
cv::Mat LabelImage16(const Scan& scan);

// Puts points back along the rays from a changed range image (CV_32F metres, 0 or NaN = no return). Cells
// that were valid keep their measured ray (point / |point|); other cells use `direction`. Returns the new
// scan; all other channels are copied. Cells listed in `mark_synthesized` (CV_8U, non-zero) get
// synthesized = 255.
Scan WithRange(const Scan& scan, const cv::Mat& range, const cv::Mat& mark_synthesized = cv::Mat());

}  // namespace lidarshop
