// Conditional region growing over an organized scan's grid mesh: the thesis's "mesh front iterator". A front
// of cells starts at a seed and moves to 4-connected neighbours joined by the grid mesh (both returned, range
// jump within max_range_jump_ratio, as scan/scan_mesh.h joins them) and accepted by a pluggable condition.
//
//   RegionGrowingOptions options;
//   cv::Mat region = GrowRegion(scan, {row, col}, options, NormalAngleCondition(scan, 10.0));
#pragma once

#include <functional>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct RegionGrowingOptions {
  double max_range_jump_ratio = 0.1;  // grid mesh edge rule: |r_a - r_b| <= ratio · min(r_a, r_b), > 0
  int64_t min_region_cells = 1;       // SegmentByRegionGrowing: smaller regions get kNoLabel, >= 1
  void Check() const;                 // throws OptionsError
};
template <>
const StructInfo& InfoOf<RegionGrowingOptions>();

// Whether the front may move from cell `from` to its neighbour `to` (cv::Point(col, row)).
using GrowCondition = std::function<bool(cv::Point from, cv::Point to)>;

// Neighbours whose normals (scan.normal, needed) differ by less than `max_angle_deg`: smooth surfaces.
GrowCondition NormalAngleCondition(const Scan& scan, double max_angle_deg);

// The cells reached from `seed` (CV_8U 255/0, rows x cols). Throws InputError when the seed is outside the
// scan or has no return.
cv::Mat GrowRegion(const Scan& scan, cv::Point seed, const RegionGrowingOptions& options,
                   const GrowCondition& condition);

// Every returned cell in one region: regions grown in row-major order of their first cell. Labels CV_32S
// 0, 1, …; kNoLabel for cells without a return or in regions smaller than min_region_cells. `num_regions`
// (optional) receives the number of labels given.
cv::Mat SegmentByRegionGrowing(const Scan& scan, const RegionGrowingOptions& options,
                               const GrowCondition& condition, int* num_regions = nullptr);

}  // namespace lidarshop
