#include "lidarshop/fill/remove.h"

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

void RemoveOptions::Check() const {
  segment.Check();
  fill.Check();
  CheckOption(margin_cells >= 0 && margin_cells <= 100,
              fmt::format("RemoveOptions.margin_cells must be in [0, 100], got {}", margin_cells));
}

RemoveResult RemoveObject(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options,
                          Progress* progress) {
  options.Check();
  RemoveResult result;
  result.cut = SegmentObject(scan, strokes, options.segment);
  result.hole = GrowHole(result.cut.mask, options.margin_cells);
  if (progress) progress->Restart("fill", cv::countNonZero(result.hole));
  result.fill = FillScan(scan, result.hole, options.fill, progress);
  if (options.keep_object) result.behind = MaskScan(result.fill.scan, result.fill.filled & (result.cut.mask != 0));
  return result;
}

}  // namespace lidarshop
