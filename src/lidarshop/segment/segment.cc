#include "lidarshop/segment/segment.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/render/render_layout.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

void CutWeights::Check() const { Validate(*this); }

void SegmentOptions::Check() const { Validate(*this); }

void WholeObjectOptions::Check() const { Validate(*this); }

std::string SegmentResult::Summary() const {
  std::string summary = fmt::format(
      "{} object cells, flow {:.1f}, {:.3f} s (features {:.3f}, models {:.3f}, graph {:.3f}, "
      "max-flow {:.3f})",
      object_cells, flow, timings.total_s, timings.features_s, timings.models_s, timings.graph_s,
      timings.maxflow_s);
  if (coarse_factor > 1)
    summary += fmt::format(", cut on a level of 1 in {} rays each way, outline re-cut at full resolution",
                           coarse_factor);
  return summary;
}

namespace {
cv::Mat ColorPicture(const Scan& scan) {
  if (scan.has_color()) return scan.color.clone();
  cv::Mat grey(scan.rows, scan.cols, CV_8U, cv::Scalar(128));  // neither colour nor intensity: plain grey
  if (scan.has_intensity()) scan.intensity.convertTo(grey, CV_8U, 255.0);
  cv::Mat rgb;
  cv::cvtColor(grey, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}
}  // namespace

cv::Mat GrabCutFromStrokes(const Scan& scan, const cv::Mat& strokes, int iterations,
                           int probable_radius_cells) {
  CheckScan(scan);
  LIDARSHOP_CHECK(strokes.size() == cv::Size(scan.cols, scan.rows) && strokes.type() == CV_8U);
  cv::Mat gc_mask(scan.rows, scan.cols, CV_8U, cv::Scalar(cv::GC_PR_BGD));
  if (probable_radius_cells > 0) {
    cv::Mat object_strokes = strokes == kStrokeObject, near;
    const int k = 2 * probable_radius_cells + 1;
    cv::dilate(object_strokes, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    gc_mask.setTo(cv::GC_PR_FGD, near);
  }
  gc_mask.setTo(cv::GC_BGD, scan.valid == 0);
  gc_mask.setTo(cv::GC_BGD, strokes == kStrokeBackground);
  gc_mask.setTo(cv::GC_FGD, strokes == kStrokeObject);
  cv::Mat image = ColorPicture(scan), bgd_model, fgd_model;
  cv::grabCut(image, gc_mask, cv::Rect(), bgd_model, fgd_model, iterations, cv::GC_INIT_WITH_MASK);
  cv::Mat out = (gc_mask == cv::GC_FGD) | (gc_mask == cv::GC_PR_FGD);
  out.setTo(0, scan.valid == 0);
  return out;
}

namespace {

// Object pixels (`mask`, 255/0) tinted and outlined in a colour that stands out from them and their
// surroundings.
void TintObject(cv::Mat* picture, const cv::Mat& mask) {
  // The colour is chosen against the object and a band around it: the outline lies on both.
  cv::Mat surroundings;
  cv::dilate(mask, surroundings, cv::Mat(), cv::Point(-1, -1), 5);
  const cv::Vec3b overlay_rgb = ContrastingOverlayColor(*picture, surroundings);
  const cv::Scalar overlay(overlay_rgb[0], overlay_rgb[1], overlay_rgb[2]);
  cv::Mat tinted;
  cv::addWeighted(*picture, 0.6, cv::Mat(picture->size(), CV_8UC3, overlay), 0.4, 0, tinted);
  tinted.copyTo(*picture, mask);
  cv::Mat eroded;
  cv::erode(mask, eroded, cv::Mat());
  picture->setTo(overlay, mask & ~eroded);
}

}  // namespace

cv::Mat SegmentOverlayPicture(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes,
                              cv::Size picture_size, const cv::Mat& picture_strokes) {
  CheckScan(scan);
  cv::Mat picture = ResampleNearest(SegmentOverlay(scan, cv::Mat(), cv::Mat()), picture_size).clone();
  if (!mask.empty()) {
    LIDARSHOP_CHECK(mask.size() == cv::Size(scan.cols, scan.rows) && mask.type() == CV_8U);
    TintObject(&picture, ResampleNearest(mask != 0, picture_size));
  }
  cv::Mat shown = picture_strokes;
  if (shown.empty() && !strokes.empty()) {
    LIDARSHOP_CHECK(strokes.size() == cv::Size(scan.cols, scan.rows) && strokes.type() == CV_8U);
    shown = ResampleNearest(strokes, picture_size);
  }
  if (!shown.empty()) {
    LIDARSHOP_CHECK(shown.size() == picture_size && shown.type() == CV_8U);
    picture.setTo(cv::Scalar(255, 0, 0), shown == kStrokeBackground);
    picture.setTo(cv::Scalar(0, 255, 0), shown == kStrokeObject);
  }
  return picture;
}

cv::Mat SegmentOverlay(const Scan& scan, const cv::Mat& mask, const cv::Mat& strokes) {
  CheckScan(scan);
  cv::Mat picture = ColorPicture(scan);
  // Cells without a return in dark blue-grey.
  picture.setTo(cv::Scalar(30, 30, 50), scan.valid == 0);
  if (!mask.empty()) {
    LIDARSHOP_CHECK(mask.size() == picture.size() && mask.type() == CV_8U);
    TintObject(&picture, mask != 0);
  }
  if (!strokes.empty()) {
    LIDARSHOP_CHECK(strokes.size() == picture.size() && strokes.type() == CV_8U);
    const int radius = OverlayStrokeRadius(picture.size());
    const cv::Mat disc =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
    for (const auto& [kind, colour] : {std::pair{kStrokeBackground, cv::Scalar(255, 0, 0)},
                                       std::pair{kStrokeObject, cv::Scalar(0, 255, 0)}}) {
      cv::Mat wide, rim;
      cv::dilate(strokes == kind, wide, disc);
      if (radius > 1) {  // a dark rim keeps a thick stroke readable on any background
        cv::dilate(wide, rim, cv::Mat());
        picture.setTo(cv::Scalar(0, 0, 0), rim);
      }
      picture.setTo(colour, wide);
    }
  }
  return picture;
}

}  // namespace lidarshop
