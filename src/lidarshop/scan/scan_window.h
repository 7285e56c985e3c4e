// A window of a scan without a copy, for an edit that reads only the cells around what it changes (the fill's
// window around its hole, fill/fill.h), so that its memory follows the edit and not the station.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// CropScan(scan, window) sharing `scan`'s buffers: every channel and attribute is a region of the scan's own
// (cv::Mat ROI, rows not continuous), the grid's angles those of the window's columns and rows, pose, name and
// metadata kept. Writing into the view writes into `scan`: it is for readers (a const Scan&). Throws
// std::logic_error when `window` is not inside the scan.
Scan CropScanView(const Scan& scan, const cv::Rect& window);

}  // namespace lidarshop
