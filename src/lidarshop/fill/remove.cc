#include "lidarshop/fill/remove.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

void RemoveOptions::Check() const { Validate(*this); }

RemoveResult RemoveObject(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options,
                          Progress* progress) {
  options.Check();
  RemoveResult result;
  result.cut = SegmentObject(scan, strokes, options.segment);
  // The cut's cells with a return; the enclosed ones by this option alone (the cut may have added them).
  cv::Mat object = (result.cut.mask != 0) & (scan.valid != 0);
  if (options.fill_enclosed_no_return) object |= EnclosedNoReturnCells(object, scan.valid);
  result.hole = GrowHole(object, options.margin_cells);
  if (progress) progress->Restart("fill", cv::countNonZero(result.hole));
  result.fill = FillScan(scan, result.hole, options.fill, progress);
  if (options.keep_object)
    result.behind = MaskScan(result.fill.scan, result.fill.filled & (result.cut.mask != 0));
  result.warnings = result.cut.warnings;
  result.warnings.insert(result.warnings.end(), result.fill.warnings.begin(), result.fill.warnings.end());
  return result;
}

}  // namespace lidarshop
