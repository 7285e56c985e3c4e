#include "lidarshop/site/transients.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/site/grid_lookup.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void TransientOptions::Check() const { Validate(*this); }
void CleanOptions::Check() const { Validate(*this); }

template <>
const StructInfo& InfoOf<TransientOptions>() {
  static const StructInfo info = [] {
    StructBuilder<TransientOptions> b("TransientOptions", "points another station saw through");
    b.Field(&TransientOptions::range_noise_sigma_m, "range_noise_sigma_m", "σ of the stations' range noise")
        .Unit("m")
        .Min(0);
    b.Field(&TransientOptions::sigma_multiple, "sigma_multiple", "the margin holds this many σ").Min(0);
    b.Field(&TransientOptions::min_margin_m, "min_margin_m", "seen through only this far behind, at least")
        .Unit("m")
        .Min(0);
    b.Field(&TransientOptions::footprint_multiple, "footprint_multiple",
            "the ray footprint (range x angular step) times this is added to the margin")
        .Min(0);
    b.Field(&TransientOptions::neighbourhood_cells, "neighbourhood_cells",
            "cells on each side of the ray's cell that must all see farther")
        .Unit("cells")
        .Range(0, 8);
    b.Field(&TransientOptions::min_region_cells, "min_region_cells", "smaller transient regions are kept")
        .Unit("cells")
        .Min(1);
    b.Field(&TransientOptions::grow_cells, "grow_cells",
            "transient regions grow this far over depth-continuous unconfirmed neighbours")
        .Unit("cells")
        .Range(0, 32);
    b.Field(&TransientOptions::grow_max_range_jump, "grow_max_range_jump",
            "largest relative range step between grown neighbours")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CleanOptions>() {
  static const StructInfo info = [] {
    StructBuilder<CleanOptions> b("CleanOptions", "remove what moved between stations, fill the holes");
    b.Field(&CleanOptions::transients, "transients", "what counts as transient");
    b.Field(&CleanOptions::fill, "fill", "the fill of the removed points' holes");
    b.Field(&CleanOptions::margin_cells, "margin_cells", "the removed cells are grown by this before filling")
        .Unit("cells")
        .Range(0, 32);
    b.Field(&CleanOptions::fill_holes, "fill_holes", "fill the holes (else: cells without a return)");
    b.Field(&CleanOptions::from_stations, "from_stations",
            "fill from what the other stations measured first, synthesize only the rest");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CleanStationSummary>() {
  static const StructInfo info = [] {
    using Station = CleanStationSummary;
    StructBuilder<Station> b("CleanStationSummary", "a station of clean --json");
    b.Field(&Station::file, "file", "the file it was read from");
    b.Field(&Station::scan, "scan", "its scan in that file, from 0");
    b.Field(&Station::output, "output", "the file it was written to");
    b.Field(&Station::returns, "returns", "cells with a return before the clean").Unit("cells");
    b.Field(&Station::removed, "removed", "transient cells removed").Unit("cells");
    b.Field(&Station::seen_through, "seen_through",
            "cells another station saw through (before the region filter and growth)")
        .Unit("cells");
    b.Field(&Station::confirmed, "confirmed", "cells another station measured the same (static)")
        .Unit("cells");
    b.Field(&Station::filled, "filled", "hole cells the fill gave a synthesized return").Unit("cells");
    b.Field(&Station::from_station, "from_station", "hole cells given another station's measurement")
        .Unit("cells");
    b.Field(&Station::removed_mask, "removed_mask",
            "the picture of the removed cells (--removed-masks), \"\" for none");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CleanSummary>() {
  static const StructInfo info = [] {
    StructBuilder<CleanSummary> b("CleanSummary", "the --json of clean: what moved, removed and filled");
    b.Field(&CleanSummary::stations, "stations", "every station, in order");
    b.Field(&CleanSummary::removed, "removed", "transient cells removed, every station").Unit("cells");
    b.Field(&CleanSummary::warnings, "warnings",
            "the fills' warnings, naming the station, one sentence each");
    return b.Build();
  }();
  return info;
}

CleanSummary SummarizeClean(const std::vector<Scan>& stations, const CleanResult& result) {
  CleanSummary summary;
  for (size_t k = 0; k < stations.size(); ++k) {
    const StationTransients& found = result.transients.stations[k];
    CleanStationSummary& station = summary.stations.emplace_back();
    station.returns = stations[k].CountValid();
    station.removed = found.transient_cells;
    station.seen_through = found.seen_through_cells;
    station.confirmed = found.confirmed_cells;
    station.filled = result.filled_cells[k];
    station.from_station = result.from_station_cells[k];
    summary.removed += found.transient_cells;
  }
  summary.warnings = result.warnings;
  return summary;
}

namespace {

constexpr uint8_t kNoEvidence = 0, kSeenThrough = 1, kConfirmed = 2;

// What station `b` says of each point of station `a`: kSeenThrough, kConfirmed or kNoEvidence, per cell.
cv::Mat EvidenceFrom(const Scan& a, const Scan& b, const GridLookup& b_grid, const TransientOptions& o) {
  cv::Mat evidence(a.rows, a.cols, CV_8U, cv::Scalar(kNoEvidence));
  const Eigen::Matrix4d b_from_a = b.world_from_scanner.inverse() * a.world_from_scanner;
  const int n = o.neighbourhood_cells;
  const double step = b_grid.step_rad();
  ParallelFor(a.rows, [&](int64_t row) {
    const uint8_t* valid = a.valid.ptr<uint8_t>(static_cast<int>(row));
    const cv::Vec3f* point = a.point.ptr<cv::Vec3f>(static_cast<int>(row));
    uint8_t* out = evidence.ptr<uint8_t>(static_cast<int>(row));
    for (int col = 0; col < a.cols; ++col) {
      if (valid[col] == 0) continue;
      const Eigen::Vector3d p_b =
          b_from_a.topLeftCorner<3, 3>() * Eigen::Vector3d(point[col][0], point[col][1], point[col][2]) +
          b_from_a.topRightCorner<3, 1>();
      int r = 0, c = 0;
      if (!b_grid.Cell(p_b, &r, &c)) continue;
      const double d = p_b.norm();
      const double margin =
          o.min_margin_m + o.sigma_multiple * o.range_noise_sigma_m + o.footprint_multiple * d * step;
      if (b.valid.at<uint8_t>(r, c) != 0 && std::abs(b.range.at<float>(r, c) - d) <= margin) {
        out[col] = kConfirmed;
        continue;
      }
      if (r < n || c < n || r + n >= b.rows || c + n >= b.cols) continue;
      bool through = true;
      for (int dr = -n; dr <= n && through; ++dr) {
        for (int dc = -n; dc <= n; ++dc) {
          // A cell without a return tells nothing: the ray may have met a dark or mirroring surface.
          if (b.valid.at<uint8_t>(r + dr, c + dc) == 0 || b.range.at<float>(r + dr, c + dc) <= d + margin) {
            through = false;
            break;
          }
        }
      }
      if (through) out[col] = kSeenThrough;
    }
  });
  return evidence;
}

// Grows the non-zero cells of `reason` by one cell at a time, `steps` times, into valid cells that no station
// confirmed and whose range is within `max_jump` (relative) of a neighbour already in; a grown cell takes that
// neighbour's reason (the first in row order). Sequential, so the result does not depend on threads.
void GrowOverContinuousDepth(const Scan& scan, const cv::Mat& confirmed, int steps, double max_jump,
                             cv::Mat* reason) {
  if (cv::countNonZero(*reason) == 0) return;  // nothing moved: no pass over the grid
  for (int step = 0; step < steps; ++step) {
    cv::Mat next = reason->clone();
    for (int r = 0; r < scan.rows; ++r) {
      for (int c = 0; c < scan.cols; ++c) {
        if (reason->at<uint8_t>(r, c) != 0 || scan.valid.at<uint8_t>(r, c) == 0 ||
            confirmed.at<uint8_t>(r, c) != 0)
          continue;
        const float range = scan.range.at<float>(r, c);
        for (int dr = -1; dr <= 1 && next.at<uint8_t>(r, c) == 0; ++dr) {
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = r + dr, cc = c + dc;
            if (rr < 0 || cc < 0 || rr >= scan.rows || cc >= scan.cols || reason->at<uint8_t>(rr, cc) == 0)
              continue;
            if (std::abs(scan.range.at<float>(rr, cc) - range) <= max_jump * range) {
              next.at<uint8_t>(r, c) = reason->at<uint8_t>(rr, cc);
              break;
            }
          }
        }
      }
    }
    *reason = next;
  }
}

}  // namespace

TransientResult FindTransients(const std::vector<Scan>& stations, const TransientOptions& options,
                               Progress* progress) {
  options.Check();
  if (stations.size() < 2)
    throw InputError(fmt::format("finding what moved needs two stations or more, got {}", stations.size()));
  std::vector<GridLookup> grids;
  for (size_t i = 0; i < stations.size(); ++i) {
    CheckScan(stations[i]);
    if (!HasRayDirections(stations[i]) || stations[i].rows < 2 || stations[i].cols < 2)
      throw InputError(fmt::format("station {} ('{}') has no grid: an unorganized cloud cannot be compared",
                                   i, stations[i].name));
    grids.emplace_back(stations[i]);
  }
  TransientResult result;
  for (size_t a = 0; a < stations.size(); ++a) {
    const Scan& scan = stations[a];
    StationTransients out;
    out.seen_through_by = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    out.confirmed = cv::Mat::zeros(scan.rows, scan.cols, CV_8U);
    for (size_t b = 0; b < stations.size(); ++b) {
      if (b == a) continue;
      const cv::Mat evidence = EvidenceFrom(scan, stations[b], grids[b], options);
      out.confirmed.setTo(255, evidence == kConfirmed);
      out.seen_through_by.setTo(static_cast<int>(std::min<size_t>(b + 1, 255)),
                                (evidence == kSeenThrough) & (out.seen_through_by == 0));
      if (progress != nullptr) progress->Advance();
    }
    // A point one station saw and another saw through is kept: the seeing station is the better witness at
    // a grazing ray (and a point seen twice is the wall, not the passer-by).
    out.seen_through_by.setTo(0, out.confirmed);
    out.seen_through_cells = cv::countNonZero(out.seen_through_by);
    out.seen_through_by.setTo(0,
                              WithoutSmallRegions(out.seen_through_by != 0, options.min_region_cells) == 0);
    GrowOverContinuousDepth(scan, out.confirmed, options.grow_cells, options.grow_max_range_jump,
                            &out.seen_through_by);
    out.transient = out.seen_through_by != 0;
    out.transient_cells = cv::countNonZero(out.transient);
    out.confirmed_cells = cv::countNonZero(out.confirmed);
    result.stations.push_back(std::move(out));
  }
  return result;
}

CleanResult CleanStations(const std::vector<Scan>& stations, const CleanOptions& options,
                          Progress* progress) {
  options.Check();
  CleanResult result;
  result.transients = FindTransients(stations, options.transients, progress);
  for (size_t i = 0; i < stations.size(); ++i) {
    const StationTransients& found = result.transients.stations[i];
    if (found.transient_cells == 0) {
      result.stations.push_back(stations[i]);
      result.filled_cells.push_back(0);
      result.from_station_cells.push_back(0);
      continue;
    }
    const cv::Mat hole = GrowHole(found.transient, options.margin_cells);
    if (!options.fill_holes) {
      result.stations.push_back(MaskScan(stations[i], hole == 0));
      result.filled_cells.push_back(0);
      result.from_station_cells.push_back(0);
      continue;
    }
    if (!options.from_stations) {
      FillResult filled = FillScan(MaskScan(stations[i], hole == 0), hole, options.fill);
      for (const std::string& warning : filled.warnings)
        result.warnings.push_back(fmt::format("station {}: {}", i, warning));
      result.filled_cells.push_back(filled.synthesized_cells);
      result.from_station_cells.push_back(0);
      result.stations.push_back(std::move(filled.scan));
      continue;
    }
    // The other stations, and their indices in the site.
    std::vector<Scan> others;
    std::vector<int> index_of_other;
    for (size_t j = 0; j < stations.size(); ++j) {
      if (j == i) continue;
      others.push_back(stations[j]);
      index_of_other.push_back(static_cast<int>(j));
    }
    FromStationsOptions from;
    from.range_noise_sigma_m = options.transients.range_noise_sigma_m;
    from.object_margin_cells = options.margin_cells;
    from.fill = options.fill;
    FromStationsResult filled = FillFromStations(stations[i], hole, others, from);
    for (const std::string& warning : filled.warnings)
      result.warnings.push_back(fmt::format("station {}: {}", i, warning));
    // from_station names the station in the site's list, not in `others`.
    cv::Mat& tag = filled.scan.from_station;
    for (int r = 0; r < tag.rows; ++r) {
      uint8_t* t = tag.ptr<uint8_t>(r);
      const uint8_t* mine = filled.from_station.ptr<uint8_t>(r);
      for (int c = 0; c < tag.cols; ++c)
        if (mine[c] != 0) t[c] = static_cast<uint8_t>(std::min(index_of_other[mine[c] - 1] + 1, 255));
    }
    result.filled_cells.push_back(filled.synthesized_cells);
    result.from_station_cells.push_back(filled.from_station_cells);
    result.stations.push_back(std::move(filled.scan));
  }
  return result;
}

}  // namespace lidarshop
