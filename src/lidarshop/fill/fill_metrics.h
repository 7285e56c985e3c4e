// Quality of a hole fill against ground truth: the same scan taken without the removed object (synthetic
// scenes scanned twice with the same seed). Every statistic is over the cells of the hole only.
#pragma once

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct FillMetricsOptions {
  double within_m = 0.02;  // "within" tolerance of the range error, metres (the 20 mm of the share)
  // A filled point farther than this from the true surface floats, metres: from every truth point and from the
  // truth grid's triangles around its own cell (far ground at grazing incidence is sampled a metre apart).
  double floating_m = 0.10;
  int normal_window_radius = 2;  // plane-fit window of the filled points' normals, cells (5 x 5)
  int seam_band_cells = 8;       // width of the band outside the hole where the reference jump is measured
};
template <>
const StructInfo& InfoOf<FillMetricsOptions>();

struct FillMetrics {
  int64_t hole_cells = 0;
  int64_t compared_cells = 0;  // hole cells with a return in both the fill and the truth
  double range_rmse_mm = 0;    // against the truth's noise-free range (true_range) where it has one
  double range_mae_mm = 0;
  double within_share = 0;      // share of compared cells within `within_m`
  double normal_error_deg = 0;  // mean angle between plane-fit normals of the fill and the true normals
  double seam_mm = 0;           // mean |range jump| across edges from a filled cell to a known one
  double seam_outside_mm = 0;   // the same statistic on known-known edges in a band around the hole
  double floating_share = 0;    // share of synthesized points farther than floating_m from the truth
  double return_accuracy = 0;   // share of hole cells whose return / no-return matches the truth
  double color_psnr_db = 0;     // RGB PSNR over compared cells (0 when a scan has no colour)
  cv::Mat floating_cells;       // CV_8U rows x cols, 255 = a synthesized point counted as floating
};

// `filled` and `truth` share the grid; `hole` is CV_8U non-zero. Throws InputError on mismatched sizes.
FillMetrics MeasureFill(const Scan& filled, const Scan& truth, const cv::Mat& hole,
                        const FillMetricsOptions& options = {});

}  // namespace lidarshop
