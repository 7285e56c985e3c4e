// Every per-cell channel of a Scan, visited in one order: the operations that copy or resample all of them
// (CropScan, PasteScan, DecimateScan) go through this list, so a channel added to Scan is added here once.
// Internal to the scan module.
#pragma once

#include <cmath>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop::scan_internal {

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

}  // namespace lidarshop::scan_internal
