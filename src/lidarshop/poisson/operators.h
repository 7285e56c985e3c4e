// Discrete differential operators on images, chosen so that they compose exactly:
//
//   BackwardDivergence(ForwardGradient(I)) == Laplacian5(I)      (bit for bit up to float rounding)
//
// Images are H x W cv::Mat of CV_32FC(n) or CV_64FC(n) (other depths are converted to CV_32F); every channel
// is treated independently and the output keeps the (float) depth and channel count of the input.
//
// Boundary handling (natural / Neumann boundary on the image border: no flux leaves the image):
//   * gradient samples live on the edges between a pixel and its right / lower neighbour; the last column
//     of gx and the last row of gy would be edges leaving the image and are 0;
//   * the divergence ignores edges leaving the image, i.e. it treats gx(y, −1), gx(y, W−1), gy(−1, x) and
//     gy(H−1, x) as 0 whatever the input holds there;
//   * so the Laplacian of a pixel sums I(n) − I(p) over its in-image 4-neighbours only (3 at an edge, 2 at
//     a corner).
// This is the discretisation of Pérez, Gangnet, Blake, "Poisson Image Editing", SIGGRAPH 2003, eq. 7–8.
#pragma once

#include <opencv2/core.hpp>

namespace lidarshop {

// Forward differences of an H x W image:
//   gx(y, x) = I(y, x+1) − I(y, x)  for x < W−1, and 0 in the last column;
//   gy(y, x) = I(y+1, x) − I(y, x)  for y < H−1, and 0 in the last row.
// Both are H x W with the image's channel count, CV_64F for CV_64F input and CV_32F otherwise.
struct ImageGradient {
  cv::Mat gx;  // H x W x n, horizontal differences (to the right neighbour)
  cv::Mat gy;  // H x W x n, vertical differences (to the lower neighbour, row y+1 is further down)
};
ImageGradient ForwardGradient(const cv::Mat& image);

// Backward differences: div(y, x) = gx(y, x) − gx(y, x−1) + gy(y, x) − gy(y−1, x), with the edges leaving the
// image taken as 0 (see above). gx and gy must have the same size, channels and depth (CV_32F or CV_64F);
// throws InputError otherwise. Output: H x W x n of their depth.
cv::Mat BackwardDivergence(const cv::Mat& gx, const cv::Mat& gy);

// 5-point Laplacian with the Neumann border: L(p) = sum over in-image 4-neighbours n of (I(n) − I(p)).
cv::Mat Laplacian5(const cv::Mat& image);

}  // namespace lidarshop
