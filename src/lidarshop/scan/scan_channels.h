// Every per-cell channel of a Scan, visited in one order: the operations that copy or resample all of them
// (CropScan, PasteScan, DecimateScan) go through this list, so a channel added to Scan is added here once.
// Internal to the scan module.
#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop::scan_internal {

// DirectionsFromGrid written into `directions`, reusing its buffer when it has the grid's size and type
// (FitGrid replaces a station's directions without a second direction image).
void FillDirectionsFromGrid(const ScanGrid& grid, cv::Mat* directions);

// Visits every per-cell channel of `scan` with its no-return value (MaskScan's).
template <typename ScanT, typename Visit>
void ForEachChannel(ScanT& scan, Visit visit) {
  visit(scan.direction, cv::Scalar::all(0));
  visit(scan.valid, cv::Scalar(0));
  visit(scan.range, cv::Scalar(0));
  visit(scan.point, cv::Scalar::all(0));
  visit(scan.intensity, cv::Scalar(0.5));
  visit(scan.color, cv::Scalar::all(0));
  visit(scan.label, cv::Scalar(kNoLabel));
  visit(scan.normal, cv::Scalar::all(0));
  visit(scan.curvature, cv::Scalar(NAN));
  visit(scan.true_range, cv::Scalar(0));
  visit(scan.synthesized, cv::Scalar(0));
  visit(scan.from_station, cv::Scalar(0));
}

// A scan of rows x cols with `scan`'s pose, name and file-level records, and every channel and attribute
// `scan` has made by `resample(channel)` (a rows x cols matrix of the channel's type). The grid is left to
// the caller.
template <typename Resample>
Scan ResampledScan(const Scan& scan, int rows, int cols, Resample resample) {
  Scan out;
  out.rows = rows;
  out.cols = cols;
  out.world_from_scanner = scan.world_from_scanner;
  out.name = scan.name;
  out.source_records = scan.source_records;
  out.source_metadata = scan.source_metadata;
  // Pairs the channels of `scan` and `out` in the same order.
  std::vector<cv::Mat*> targets;
  ForEachChannel(out, [&](cv::Mat& channel, const cv::Scalar&) { targets.push_back(&channel); });
  size_t i = 0;
  ForEachChannel(scan, [&](const cv::Mat& channel, const cv::Scalar&) {
    if (!channel.empty()) *targets[i] = resample(channel);
    ++i;
  });
  for (const auto& [name, values] : scan.attributes) out.attributes[name] = resample(values);
  return out;
}

}  // namespace lidarshop::scan_internal
