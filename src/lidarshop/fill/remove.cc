#include "lidarshop/fill/remove.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {

void RemoveOptions::Check() const { Validate(*this); }

cv::Mat EnclosedNoReturnCells(const cv::Mat& mask, const cv::Mat& valid) {
  // Flood the outside of the mask from every border cell (4-connected); what stays unflooded is enclosed.
  cv::Mat outside = (mask == 0) / 255;  // 1 = not the object
  cv::Mat padded;
  cv::copyMakeBorder(outside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(1));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(2), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
  const cv::Mat inner = padded(cv::Rect(1, 1, mask.cols, mask.rows)) == 1;  // outside the mask, not reached
  return inner & (valid == 0);
}

RemoveResult RemoveObject(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options,
                          Progress* progress) {
  options.Check();
  RemoveResult result;
  result.cut = SegmentObject(scan, strokes, options.segment);
  cv::Mat object = result.cut.mask != 0;
  if (options.fill_enclosed_no_return) object |= EnclosedNoReturnCells(object, scan.valid);
  result.hole = GrowHole(object, options.margin_cells);
  if (progress) progress->Restart("fill", cv::countNonZero(result.hole));
  result.fill = FillScan(scan, result.hole, options.fill, progress);
  if (options.keep_object)
    result.behind = MaskScan(result.fill.scan, result.fill.filled & (result.cut.mask != 0));
  return result;
}

}  // namespace lidarshop
