#include "lidarshop/pointset/superpixels.h"

#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/pointset/quickshift.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/plugin.h"

namespace lidarshop {

void SuperpixelOptions::Check() const { Validate(*this); }

cv::Mat ScanSuperpixels(const Scan& scan, const SuperpixelOptions& options, int* num_superpixels) {
  options.Check();
  if (scan.num_cells() == 0) throw InputError("superpixels: the scan has no cells");
  // Channels in [0, 255]: colour (or intensity) and log range scaled to the scan's own range span.
  std::vector<cv::Mat> channels;
  if (scan.has_color()) {
    cv::Mat color;
    scan.color.convertTo(color, CV_32FC3);
    cv::split(color, channels);
  } else if (scan.has_intensity()) {
    cv::Mat intensity;
    scan.intensity.convertTo(intensity, CV_32F, 255.0);
    channels.push_back(intensity);
  }  // neither: the range alone
  if (channels.empty() && !(options.range_weight > 0.0 && scan.CountValid() > 0)) {
    throw InputError(
        "superpixels: the scan has neither colour nor intensity, and the range is not used (range_weight 0 "
        "or no return): nothing to group by");
  }
  if (options.range_weight > 0.0 && scan.CountValid() > 0) {
    cv::Mat log_range;
    cv::log(cv::max(scan.range, 1e-3), log_range);
    double low, high;
    cv::minMaxLoc(log_range, &low, &high, nullptr, nullptr, scan.valid);
    cv::Mat scaled = (log_range - low) * (255.0 * options.range_weight / std::max(high - low, 1e-6));
    scaled.setTo(0, scan.valid == 0);
    channels.push_back(scaled);
  }
  cv::Mat image;
  cv::merge(channels, image);
  cv::Mat labels;
  if (options.method == SuperpixelMethod::kSlic) {
    // OpenCV ximgproc through lidarshop's plugin (util/plugin.h: loaded on first use).
    static const auto slic =
        OpenCvPluginFunction<void(const cv::Mat*, int, float, int, cv::Mat*, int*)>("lidarshop_slic");
    int count = 0;
    slic(&image, options.region_cells, static_cast<float>(options.ruler), options.iterations, &labels,
         &count);
    if (num_superpixels) *num_superpixels = count;
  } else if (options.method == SuperpixelMethod::kQuickShift) {
    cv::Mat features;
    image.convertTo(features, CV_32F, options.quickshift_ratio);
    const cv::Mat mask = scan.valid.empty() ? cv::Mat() : (scan.valid != 0);
    labels = QuickShift(features, mask, {options.quickshift_kernel_size, options.quickshift_max_dist},
                        num_superpixels);
  } else {
    // The graph segmentation takes up to 3 channels of 8 bits or floats; keep the first three.
    if (image.channels() > 3) {
      std::vector<cv::Mat> first(channels.begin() + 1, channels.end());
      cv::merge(first, image);  // drop red: green, blue, range
    }
    static const auto graph = OpenCvPluginFunction<void(const cv::Mat*, double, float, int, cv::Mat*)>(
        "lidarshop_graph_segmentation");
    graph(&image, options.graph_sigma, static_cast<float>(options.graph_k), options.graph_min_cells, &labels);
    if (num_superpixels) {
      double high;
      cv::minMaxLoc(labels, nullptr, &high);
      *num_superpixels = static_cast<int>(high) + 1;
    }
  }
  if (!scan.valid.empty()) labels.setTo(kNoLabel, scan.valid == 0);
  return labels;
}

}  // namespace lidarshop
