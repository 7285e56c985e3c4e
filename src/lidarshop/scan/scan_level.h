// A coarser level of a scan: every factor-th ray in each direction, for the operations that work coarse to fine
// (segment.h's cut of a large station). Measured cells, not averages: a block's representative is one of its
// own rays, so depth steps stay steps and colours are ones the scanner recorded.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// The scan with ceil(rows / factor) x ceil(cols / factor) cells; coarse cell (r, c) is the cell of the block
// rows [r·factor, (r+1)·factor) x cols [c·factor, (c+1)·factor) nearest its centre that has a return (ties: the
// first in row-major order), or the centre cell itself (its direction, no return) when none has. Every
// channel and attribute is taken from that cell; the grid's angles are the blocks' centre columns and rows.
// factor >= 1 (1 = a copy).
Scan DecimateScan(const Scan& scan, int factor);
// The same with the cells DecimatedCells(scan, factor) gave, for a caller that keeps them.
Scan DecimateScan(const Scan& scan, const cv::Mat& cells, int factor);

// The cell of `scan` that DecimateScan(scan, factor) takes for each coarse cell, as row * scan.cols + col:
// CV_32S, ceil(rows / factor) x ceil(cols / factor). Both refuse scans of 2^31 cells or more.
cv::Mat DecimatedCells(const Scan& scan, int factor);

}  // namespace lidarshop
