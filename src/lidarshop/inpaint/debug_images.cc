#include "lidarshop/inpaint/debug_images.h"

#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"

namespace lidarshop {

cv::Mat ToRgb8(const cv::Mat& image) {
  cv::Mat eight;
  image.convertTo(eight, CV_8U);
  if (eight.channels() == 1) cv::cvtColor(eight, eight, cv::COLOR_GRAY2RGB);
  if (eight.channels() == 4) cv::cvtColor(eight, eight, cv::COLOR_RGBA2RGB);
  if (eight.channels() != 3) {
    std::vector<cv::Mat> planes;
    cv::split(eight, planes);
    cv::merge(std::vector<cv::Mat>{planes[0], planes[0], planes[0]}, eight);
  }
  return eight;
}

namespace {
cv::Mat DarkBackground(const cv::Mat& background, cv::Size size) {
  LIDARSHOP_CHECK(background.size() == size);
  cv::Mat rgb = ToRgb8(background);
  rgb.convertTo(rgb, CV_8U, 0.5);
  return rgb;
}
}  // namespace

cv::Mat RenderFillOrder(const InpaintResult& result, const cv::Mat& background) {
  cv::Mat picture = DarkBackground(background, result.fill_iteration.size());
  const int n = std::max(1, result.iterations - 1);
  cv::Mat ramp(1, 256, CV_8U), colours;
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(i) = static_cast<uint8_t>(i);
  cv::applyColorMap(ramp, colours, cv::COLORMAP_JET);  // BGR
  for (int r = 0; r < picture.rows; ++r) {
    for (int c = 0; c < picture.cols; ++c) {
      const int it = result.fill_iteration.at<int>(r, c);
      if (it < 0) continue;
      const cv::Vec3b bgr = colours.at<cv::Vec3b>(0, static_cast<int>(255.0 * it / n));
      picture.at<cv::Vec3b>(r, c) = cv::Vec3b(bgr[2], bgr[1], bgr[0]);
    }
  }
  return picture;
}

cv::Mat RenderSourceMap(const InpaintResult& result, const cv::Mat& background) {
  cv::Mat picture = DarkBackground(background, result.source_pixel.size());
  for (int r = 0; r < picture.rows; ++r) {
    for (int c = 0; c < picture.cols; ++c) {
      const cv::Vec2i s = result.source_pixel.at<cv::Vec2i>(r, c);
      if (s[0] < 0) continue;
      picture.at<cv::Vec3b>(r, c) =
          cv::Vec3b(static_cast<uint8_t>(255.0 * s[1] / std::max(1, picture.cols - 1)),
                    static_cast<uint8_t>(255.0 * s[0] / std::max(1, picture.rows - 1)), 128);
    }
  }
  return picture;
}

cv::Mat RenderSourceLocations(const InpaintResult& result, int patch_radius) {
  cv::Mat picture = ToRgb8(result.image);
  for (const FillStep& step : result.steps) {
    const cv::Point target(step.target.col, step.target.row), source(step.source.col, step.source.row);
    cv::line(picture, target, source, cv::Scalar(255, 255, 0), 1, cv::LINE_AA);
    cv::rectangle(picture, source - cv::Point(patch_radius, patch_radius),
                  source + cv::Point(patch_radius, patch_radius), cv::Scalar(0, 255, 0), 1);
    cv::circle(picture, target, 1, cv::Scalar(255, 0, 0), cv::FILLED);
  }
  return picture;
}

}  // namespace lidarshop
