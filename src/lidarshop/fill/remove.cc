#include "lidarshop/fill/remove.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

void RemoveOptions::Check() const { Validate(*this); }

RemoveResult RemoveObjectWindow(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options,
                                Progress* progress) {
  options.Check();
  RemoveResult result;
  result.cut = SegmentObject(scan, strokes, options.segment);
  // The cut's cells with a return; the enclosed ones by this option alone (the cut may have added them).
  cv::Mat object = (result.cut.mask != 0) & (scan.valid != 0);
  if (options.fill_enclosed_no_return) object |= EnclosedNoReturnCells(object, scan.valid);
  result.hole = GrowHole(object, options.margin_cells);
  if (progress) progress->Restart("fill", cv::countNonZero(result.hole));
  result.fill = FillScanWindow(scan, result.hole, options.fill, progress);
  if (options.keep_object) {
    const cv::Rect window = result.fill.Window();
    if (window == cv::Rect(0, 0, scan.cols, scan.rows)) {
      result.behind = MaskScan(result.fill.scan, result.fill.filled & (result.cut.mask != 0));
    } else {  // the scan without returns, the window's filled cells of the object pasted in
      result.behind = MaskScan(scan, cv::Mat::zeros(scan.rows, scan.cols, CV_8U));
      if (window.area() > 0) {
        PasteScan(MaskScan(result.fill.scan, result.fill.filled & (result.cut.mask(window) != 0)), window,
                  &result.behind);
      }
    }
  }
  result.warnings = result.cut.warnings;
  result.warnings.insert(result.warnings.end(), result.fill.warnings.begin(), result.fill.warnings.end());
  return result;
}

RemoveResult RemoveObject(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options,
                          Progress* progress) {
  RemoveResult result = RemoveObjectWindow(scan, strokes, options, progress);
  ExpandFill(scan, &result.fill);
  return result;
}

}  // namespace lidarshop
