// Remove an object from a scan: cut it out from strokes (segment/, two-step) and fill its cells grown by a
// margin (fill.h). With keep_object the object stays and the fill becomes a second layer behind it — the
// surface completed in the object's LiDAR shadow, so the scan looks whole from other viewpoints.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/fill/fill.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"

namespace lidarshop {

struct RemoveOptions {
  SegmentOptions segment;  // the cut (two-step by default)
  FillOptions fill;        // the fill of the hole
  // Cells the object's mask is grown by, on every side: mixed pixels at a silhouette (half object, half
  // background) belong to neither surface. In [0, 100].
  int margin_cells = 2;
  bool keep_object = false;  // true: the object stays, the fill is returned as `behind`
  // Cells without a return enclosed by the object's mask (a dark tyre, a window the ray went through) are
  // part of its silhouette: fill them too (the cut never takes them, they are not nodes of its graph).
  bool fill_enclosed_no_return = true;
  void Check() const;  // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<RemoveOptions>();

struct RemoveResult {
  SegmentResult cut;  // the object's mask and the cut's numbers
  cv::Mat hole;       // CV_8U 255 = the object's cells (and enclosed no-return cells) grown by the margin
  FillResult fill;    // fill.scan: the scan without the object (RemoveObjectWindow: its window)
  // keep_object: the filled background behind the object's own cells only (the margin ring is background in
  // front already), every other cell without a return, flagged synthesized; empty otherwise.
  Scan behind;
  // The cut's warnings then the fill's (cut.warnings, fill.warnings), one sentence each; empty when nothing
  // looks wrong.
  std::vector<std::string> warnings;
};
template <>
const StructInfo& InfoOf<RemoveResult>();

// Throws InputError for strokes of another size or without object / background cells (as SegmentObject).
RemoveResult RemoveObject(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options = {},
                          Progress* progress = nullptr);

// RemoveObject whose `fill` is FillScanWindow's: the window around the hole, not the whole scan (`behind` is
// the same); ApplyFill(result.fill, &scan) gives RemoveObject's fill.scan in a scan the caller owns.
RemoveResult RemoveObjectWindow(const Scan& scan, const cv::Mat& strokes, const RemoveOptions& options = {},
                                Progress* progress = nullptr);

}  // namespace lidarshop
