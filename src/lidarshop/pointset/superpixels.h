// Superpixels on the scan image (OpenCV ximgproc): SLIC (Achanta et al. 2012) and graph-based segmentation
// (Felzenszwalb and Huttenlocher 2004) over an image of the scan: colour when the scan has one, else
// intensity when it has that, with the range (log, so near and far weigh alike) as an extra channel (the only
// one for a scan with neither; InputError when range_weight is then 0) — and QuickShift (Vedaldi
// and Soatto 2008, pointset/quickshift.h, written here: no library in Debian has it) over the same channels
// scaled by `quickshift_ratio`, cells without a return left out.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class SuperpixelMethod { kSlic, kGraph, kQuickShift };  // "slic", "graph", "quickshift"
template <>
const EnumInfo& EnumInfoOf<SuperpixelMethod>();

struct SuperpixelOptions {
  SuperpixelMethod method = SuperpixelMethod::kSlic;
  int region_cells = 20;                // SLIC: superpixel side, cells, >= 2
  float ruler = 10.0f;                  // SLIC: compactness, > 0
  int iterations = 10;                  // SLIC iterations, >= 1
  double graph_sigma = 0.5;             // graph: Gaussian smoothing, cells, >= 0
  float graph_k = 300.0f;               // graph: larger = larger segments, > 0
  int graph_min_cells = 50;             // graph: smallest segment, cells, >= 1
  double quickshift_kernel_size = 3.0;  // QuickShift: σ of the density kernel, cells, > 0
  double quickshift_max_dist = 10.0;    // QuickShift: longest link in the joint space, > 0
  double quickshift_ratio = 0.25;       // QuickShift: weight of the [0, 255] channels against position,
                                        // > 0
  double range_weight =
      1.0;             // weight of the log-range channel against colour (both scaled to [0, 255]), >= 0
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<SuperpixelOptions>();

// CV_32S rows x cols superpixel labels 0, 1, …, kNoLabel for cells without a return (SLIC and graph see them,
// with range 0; QuickShift leaves them out). `num_superpixels` (optional) receives the count. Deterministic
// (no method draws random numbers).
cv::Mat ScanSuperpixels(const Scan& scan, const SuperpixelOptions& options, int* num_superpixels = nullptr);

}  // namespace lidarshop
