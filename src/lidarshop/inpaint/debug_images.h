// Pictures of how a fill went, for --debug and the docs. All return H x W CV_8UC3 RGB.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/inpaint.h"

namespace lidarshop {

// Filled pixels coloured by the iteration that filled them (blue = first, red = last, "jet" colour map);
// known pixels show `background`, darkened (any image of the same size: 8-bit or float in [0, 255], 1 or
// 3 channels).
cv::Mat RenderFillOrder(const InpaintResult& result, const cv::Mat& background);

// Filled pixels coloured by where they were copied from: red = source column / W, green = source row / H,
// blue = 128; known pixels darkened background. Coherent copies show as smooth ramps, patch seams as jumps.
cv::Mat RenderSourceMap(const InpaintResult& result, const cv::Mat& background);

// The result with every chosen source patch outlined (green) and every target patch centre marked (red),
// joined by a thin line: where each patch came from.
cv::Mat RenderSourceLocations(const InpaintResult& result, int patch_radius);

// Converts a float image in [0, 255] (1 or 3 channels) to 8-bit RGB.
cv::Mat ToRgb8(const cv::Mat& image);

}  // namespace lidarshop
