// FitGrid: the angular grid of a real scan from its measured points (scan.h).
//
// Per column the azimuth and per image row the elevation are the median of the valid points' angles (circular
// for azimuth), then each axis is cleaned up: lines that disagree with their neighbours by more than the
// noise allows are dropped, the rest is made monotone (pool-adjacent-violators, weighted by the number of
// points), and lines without data are interpolated linearly or extrapolated with the median step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scan/scan_channels.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 2.0 * M_PI;
// Points closer than this to the zenith or nadir (|cos φ| below it) carry no usable azimuth.
constexpr double kMinCosElevationForAzimuth = 0.1;

// The median of [begin, end) (reordered).
double Median(double* begin, double* end) {
  if (begin == end) return kNaN;
  const size_t middle = static_cast<size_t>(end - begin) / 2;
  std::nth_element(begin, begin + middle, end);
  double median = begin[middle];
  if ((end - begin) % 2 == 0) median = 0.5 * (median + *std::max_element(begin, begin + middle));
  return median;
}
double Median(std::vector<double>* values) { return Median(values->data(), values->data() + values->size()); }

// Weighted pool-adjacent-violators: the non-decreasing sequence closest to
// `values` in weighted least squares.
std::vector<double> IsotonicIncreasing(const std::vector<double>& values,
                                       const std::vector<double>& weights) {
  struct Block {
    double sum, weight;
    int count;
  };
  std::vector<Block> blocks;
  for (size_t i = 0; i < values.size(); ++i) {
    blocks.push_back({values[i] * weights[i], weights[i], 1});
    while (blocks.size() > 1) {
      const Block& last = blocks.back();
      const Block& previous = blocks[blocks.size() - 2];
      if (previous.sum / previous.weight <= last.sum / last.weight) break;
      Block merged{previous.sum + last.sum, previous.weight + last.weight, previous.count + last.count};
      blocks.pop_back();
      blocks.back() = merged;
    }
  }
  std::vector<double> result;
  result.reserve(values.size());
  for (const Block& block : blocks) result.insert(result.end(), block.count, block.sum / block.weight);
  return result;
}

// Signed median step between consecutive known lines (NaN when fewer than two are known).
double MedianStep(const std::vector<double>& medians) {
  std::vector<double> steps;
  int previous = -1;
  for (int i = 0; i < static_cast<int>(medians.size()); ++i) {
    if (std::isnan(medians[i])) continue;
    if (previous >= 0) steps.push_back((medians[i] - medians[previous]) / (i - previous));
    previous = i;
  }
  return Median(&steps);
}

// One axis: per-line medians (NaN = no data) and their point counts in, a complete monotone sequence out.
std::vector<double> FitAxis(std::vector<double> medians, const std::vector<int>& counts, double step) {
  const int n = static_cast<int>(medians.size());
  std::vector<int> known;
  for (int i = 0; i < n; ++i) {
    if (!std::isnan(medians[i])) known.push_back(i);
  }
  if (known.empty()) return {};
  if (std::isnan(step)) step = 0.0;

  // Drop lines that disagree with what their neighbours (within kWindow known lines) predict.
  if (known.size() >= 3) {
    constexpr int kWindow = 4;
    std::vector<double> residuals(known.size());
    for (size_t k = 0; k < known.size(); ++k) {
      std::vector<double> predictions;
      for (int j = std::max<int>(0, k - kWindow); j <= std::min<int>(known.size() - 1, k + kWindow); ++j) {
        if (j == static_cast<int>(k)) continue;
        predictions.push_back(medians[known[j]] + step * (known[k] - known[j]));
      }
      residuals[k] = medians[known[k]] - Median(&predictions);
    }
    std::vector<double> magnitudes(residuals.size());
    for (size_t k = 0; k < residuals.size(); ++k) magnitudes[k] = std::abs(residuals[k]);
    const double sigma = 1.4826 * Median(&magnitudes);
    const double threshold = std::max({5.0 * sigma, 0.3 * std::abs(step), 1e-9});
    std::vector<int> kept;
    for (size_t k = 0; k < known.size(); ++k) {
      if (std::abs(residuals[k]) <= threshold) {
        kept.push_back(known[k]);
      } else {
        medians[known[k]] = kNaN;
      }
    }
    if (!kept.empty()) known = kept;
  }

  // Monotone in the direction of the step.
  const double sign = step < 0 ? -1.0 : 1.0;
  std::vector<double> values(known.size()), weights(known.size());
  for (size_t k = 0; k < known.size(); ++k) {
    values[k] = sign * medians[known[k]];
    weights[k] = std::max(1, counts[known[k]]);
  }
  values = IsotonicIncreasing(values, weights);
  std::vector<double> result(n, kNaN);
  for (size_t k = 0; k < known.size(); ++k) result[known[k]] = sign * values[k];

  // Fill the gaps.
  for (int i = 0; i < known.front(); ++i) result[i] = result[known.front()] - step * (known.front() - i);
  for (int i = known.back() + 1; i < n; ++i) result[i] = result[known.back()] + step * (i - known.back());
  for (size_t k = 0; k + 1 < known.size(); ++k) {
    const int a = known[k], b = known[k + 1];
    for (int i = a + 1; i < b; ++i) {
      const double t = static_cast<double>(i - a) / (b - a);
      result[i] = (1 - t) * result[a] + t * result[b];
    }
  }
  return result;
}

}  // namespace

GridResidual MeasureGridResidual(const Scan& scan, const ScanGrid& grid) {
  // Row by row in parallel, each row's sums and maximum kept, the rows' sums added in row order: the same value
  // on any thread count, and nothing held per return. The signed offsets are the unit point's components along
  // the grid ray's local east (azimuth rising) and north (elevation rising) directions.
  struct RowSums {
    double squares = 0, max = 0, east = 0, north = 0;
    int64_t count = 0;
  };
  std::vector<RowSums> rows(scan.rows);
  const RayDirections grid_rays(grid);
  std::vector<double> sin_azimuth(scan.cols), cos_azimuth(scan.cols);
  for (int col = 0; col < scan.cols; ++col) {
    sin_azimuth[col] = std::sin(grid.azimuth_rad[col]);
    cos_azimuth[col] = std::cos(grid.azimuth_rad[col]);
  }
  ParallelFor(scan.rows, [&](int64_t r) {
    const int row = static_cast<int>(r);
    const uint8_t* valid = scan.valid.ptr<uint8_t>(row);
    const cv::Vec3f* point = scan.point.ptr<cv::Vec3f>(row);
    const double sin_elevation = std::sin(grid.elevation_rad[row]),
                 cos_elevation = std::cos(grid.elevation_rad[row]);
    RowSums& sums = rows[row];
    for (int col = 0; col < scan.cols; ++col) {
      if (!valid[col]) continue;
      const cv::Vec3d p(point[col]), d(grid_rays(row, col));
      const double angle = std::atan2(cv::norm(p.cross(d)), p.dot(d));
      sums.squares += angle * angle;
      sums.max = std::max(sums.max, angle);
      const double norm = cv::norm(p);
      if (norm > 0) {
        sums.east += (p[0] * cos_azimuth[col] - p[1] * sin_azimuth[col]) / norm;
        sums.north +=
            (p[2] * cos_elevation - sin_elevation * (p[0] * sin_azimuth[col] + p[1] * cos_azimuth[col])) /
            norm;
      }
      ++sums.count;
    }
  });
  RowSums total;
  for (const RowSums& row : rows) {
    total.squares += row.squares;
    total.max = std::max(total.max, row.max);
    total.east += row.east;
    total.north += row.north;
    total.count += row.count;
  }
  GridResidual residual;
  if (total.count == 0) return residual;
  residual.rms_rad = std::sqrt(total.squares / total.count);
  residual.max_rad = total.max;
  residual.mean_east_rad = total.east / total.count;
  residual.mean_north_rad = total.north / total.count;
  return residual;
}

void FitGrid(Scan* scan) {
  CheckScan(*scan);  // `direction` may be empty: a reader that holds no direction image
  const int rows = scan->rows, cols = scan->cols;
  // What the fit holds beside the scan is one azimuth per return (8 bytes; a station has tens of millions),
  // column by column in one array: rows are read in bands, in parallel, twice — once for their elevation
  // medians and the number of azimuths of each column, once to put the azimuths in place in row order — so the
  // samples, and every value below, are those of a serial pass.
  std::vector<double> azimuth_medians(cols, kNaN), elevation_medians(rows, kNaN);
  std::vector<int> azimuth_counts(cols, 0), elevation_counts(rows, 0);
  constexpr int kBandRows = 256;
  std::vector<std::vector<std::pair<int, double>>> row_azimuths(kBandRows);
  // The returns of one row: the counting pass (`elevations` not null) gets its elevation angles and the
  // columns of its azimuths, the placing pass (null) its (column, azimuth).
  auto row_angles = [&](int row, std::vector<double>* elevations,
                        std::vector<std::pair<int, double>>* azimuths) {
    const uint8_t* valid = scan->valid.ptr<uint8_t>(row);
    const cv::Vec3f* point = scan->point.ptr<cv::Vec3f>(row);
    for (int col = 0; col < cols; ++col) {
      if (!valid[col]) continue;
      const double x = point[col][0], y = point[col][1], z = point[col][2];
      const double horizontal = std::hypot(x, y);
      if (horizontal == 0 && z == 0) continue;
      if (elevations != nullptr) elevations->push_back(std::atan2(z, horizontal));
      if (horizontal > kMinCosElevationForAzimuth * std::hypot(horizontal, z)) {
        // The counting pass needs the column only.
        azimuths->push_back({col, elevations != nullptr ? 0.0 : std::atan2(x, y)});
      }
    }
  };
  for (int band = 0; band < rows; band += kBandRows) {
    const int band_rows = std::min(kBandRows, rows - band);
    ParallelFor(band_rows, [&](int64_t r) {
      const int row = band + static_cast<int>(r);
      std::vector<double> elevations;
      row_angles(row, &elevations, &row_azimuths[r]);
      elevation_counts[row] = static_cast<int>(elevations.size());
      elevation_medians[row] = Median(&elevations);
    });
    for (int r = 0; r < band_rows; ++r) {
      for (const auto& [col, azimuth] : row_azimuths[r]) ++azimuth_counts[col];
      row_azimuths[r].clear();
    }
  }
  std::vector<int64_t> column_start(cols + 1, 0);
  for (int col = 0; col < cols; ++col) column_start[col + 1] = column_start[col] + azimuth_counts[col];
  std::vector<double> azimuths(static_cast<size_t>(column_start[cols]));
  {
    std::vector<int64_t> next(column_start.begin(), column_start.end() - 1);
    for (int band = 0; band < rows; band += kBandRows) {
      const int band_rows = std::min(kBandRows, rows - band);
      ParallelFor(band_rows,
                  [&](int64_t r) { row_angles(band + static_cast<int>(r), nullptr, &row_azimuths[r]); });
      for (int r = 0; r < band_rows; ++r) {
        for (const auto& [col, azimuth] : row_azimuths[r]) azimuths[next[col]++] = azimuth;
        row_azimuths[r].clear();
      }
    }
  }

  ParallelFor(cols, [&](int64_t c) {  // columns are independent
    const int col = static_cast<int>(c);
    double* samples = azimuths.data() + column_start[col];
    double* samples_end = azimuths.data() + column_start[col + 1];
    if (samples == samples_end) return;
    double sum_sin = 0, sum_cos = 0;
    for (const double* angle = samples; angle != samples_end; ++angle) {
      sum_sin += std::sin(*angle);
      sum_cos += std::cos(*angle);
    }
    const double reference = std::atan2(sum_sin, sum_cos);
    for (double* angle = samples; angle != samples_end; ++angle) *angle = WrapAngle(*angle - reference);
    azimuth_medians[col] = reference + Median(samples, samples_end);
  });
  std::vector<double>().swap(azimuths);
  // Unwrap across columns so that a scan crossing θ = ±π stays continuous.
  int previous = -1;
  for (int col = 0; col < cols; ++col) {
    if (std::isnan(azimuth_medians[col])) continue;
    if (previous >= 0) {
      azimuth_medians[col] +=
          kTwoPi * std::round((azimuth_medians[previous] - azimuth_medians[col]) / kTwoPi);
    }
    previous = col;
  }

  double azimuth_step = MedianStep(azimuth_medians);
  double elevation_step = MedianStep(elevation_medians);
  // With a single known line the other axis' resolution is the best guess (scanners step both axes alike).
  if (std::isnan(azimuth_step) && !std::isnan(elevation_step)) azimuth_step = std::abs(elevation_step);
  if (std::isnan(elevation_step) && !std::isnan(azimuth_step)) elevation_step = -std::abs(azimuth_step);

  ScanGrid grid;
  grid.azimuth_rad = FitAxis(azimuth_medians, azimuth_counts, azimuth_step);
  grid.elevation_rad = FitAxis(elevation_medians, elevation_counts, elevation_step);
  if (grid.azimuth_rad.empty() || grid.elevation_rad.empty()) return;  // no usable return: nothing to fit
  grid.fitted = true;
  // A scan that holds directions gets the grid's in place (no second image); one that holds none has them
  // from the grid (ray_directions.h).
  if (!scan->direction.empty()) scan_internal::FillDirectionsFromGrid(grid, &scan->direction);

  const GridResidual residual = MeasureGridResidual(*scan, grid);
  grid.rms_residual_rad = residual.rms_rad;
  grid.max_residual_rad = residual.max_rad;
  scan->grid = std::move(grid);
}

}  // namespace lidarshop
