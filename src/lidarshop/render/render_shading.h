// The surface an orthographic picture (render_layout.h: top, front, side) sees, read off its cells: the cells'
// heights towards the viewer, smoothed over about the side of a point's square (the squares of one point are
// flat, and their steps are not the surface's), differentiated in metres (central differences). From it come
// the hillshade of `render --hillshade` and the normals of a cloud that has none.
#pragma once

#include <opencv2/core.hpp>

#include "lidarshop/render/render_layout.h"

namespace lidarshop {

// Unit normals of the surface seen, in the scanner frame of layout.cells (CV_32FC3, layout.picture_size, zero
// where no point is). `layout` must be orthographic (TowardViewer non-zero).
cv::Mat OrthographicNormals(const PictureLayout& layout);

// Shades `image` (CV_8UC3, layout.picture_size) by the surface seen, lit from azimuth 315° (north-west: up-left
// in a top view) at 45° up, as GDAL's and CloudCompare's hillshades are: a flat surface facing the viewer keeps
// its colour, slopes facing the light brighten up to 1.3 times, slopes facing away darken down to a quarter.
void Hillshade(const PictureLayout& layout, cv::Mat* image);

}  // namespace lidarshop
