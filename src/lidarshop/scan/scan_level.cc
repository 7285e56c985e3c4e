#include "lidarshop/scan/scan_level.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "lidarshop/scan/scan_channels.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

// Offsets in a factor x factor block, nearest its centre first (ties in row-major order).
std::vector<cv::Point> OffsetsByDistance(int factor) {
  std::vector<cv::Point> offsets;
  for (int dr = 0; dr < factor; ++dr)
    for (int dc = 0; dc < factor; ++dc) offsets.emplace_back(dc, dr);
  const double centre = (factor - 1) / 2.0;
  const auto distance2 = [centre](const cv::Point& p) {
    return (p.x - centre) * (p.x - centre) + (p.y - centre) * (p.y - centre);
  };
  std::stable_sort(offsets.begin(), offsets.end(),
                   [&](const cv::Point& a, const cv::Point& b) { return distance2(a) < distance2(b); });
  return offsets;
}

std::vector<double> CentreSamples(const std::vector<double>& values, int factor) {
  const int n = static_cast<int>(values.size());
  std::vector<double> out;
  for (int start = 0; start < n; start += factor)
    out.push_back(values[std::min(n - 1, start + (factor - 1) / 2)]);
  return out;
}

}  // namespace

cv::Mat DecimatedCells(const Scan& scan, int factor) {
  if (factor < 1) throw std::invalid_argument("DecimateScan: factor must be >= 1");
  if (scan.num_cells() > std::numeric_limits<int32_t>::max())
    throw std::invalid_argument("DecimateScan: a scan of 2^31 cells or more");
  const int rows = (scan.rows + factor - 1) / factor, cols = (scan.cols + factor - 1) / factor;
  const std::vector<cv::Point> offsets = OffsetsByDistance(factor);
  cv::Mat cells(rows, cols, CV_32S);
  ParallelFor(rows, [&](int64_t r) {
    int32_t* out = cells.ptr<int32_t>(static_cast<int>(r));
    const int row0 = static_cast<int>(r) * factor;
    for (int c = 0; c < cols; ++c) {
      const int col0 = c * factor;
      int32_t pick = -1;
      for (const cv::Point& o : offsets) {
        const int row = row0 + o.y, col = col0 + o.x;
        if (row >= scan.rows || col >= scan.cols || scan.valid.at<uint8_t>(row, col) == 0) continue;
        pick = row * scan.cols + col;
        break;
      }
      if (pick < 0) {
        const int row = std::min(scan.rows - 1, row0 + (factor - 1) / 2);
        const int col = std::min(scan.cols - 1, col0 + (factor - 1) / 2);
        pick = row * scan.cols + col;
      }
      out[c] = pick;
    }
  });
  return cells;
}

Scan DecimateScan(const Scan& scan, int factor) {
  CheckScan(scan);
  return DecimateScan(scan, DecimatedCells(scan, factor), factor);
}

Scan DecimateScan(const Scan& scan, const cv::Mat& cells, int factor) {
  const auto gather = [&](const cv::Mat& from) {
    cv::Mat to(cells.rows, cells.cols, from.type());
    const size_t bytes = from.elemSize();
    ParallelFor(cells.rows, [&](int64_t r) {
      const int32_t* cell = cells.ptr<int32_t>(static_cast<int>(r));
      uint8_t* out = to.ptr<uint8_t>(static_cast<int>(r));
      for (int c = 0; c < cells.cols; ++c)
        std::memcpy(out + c * bytes, from.ptr<uint8_t>(cell[c] / scan.cols) + (cell[c] % scan.cols) * bytes,
                    bytes);
    });
    return to;
  };
  Scan level = scan_internal::ResampledScan(scan, cells.rows, cells.cols, gather);
  if (static_cast<int>(scan.grid.azimuth_rad.size()) == scan.cols &&
      static_cast<int>(scan.grid.elevation_rad.size()) == scan.rows) {
    level.grid = scan.grid;
    level.grid.azimuth_rad = CentreSamples(scan.grid.azimuth_rad, factor);
    level.grid.elevation_rad = CentreSamples(scan.grid.elevation_rad, factor);
  }
  return level;
}

}  // namespace lidarshop
