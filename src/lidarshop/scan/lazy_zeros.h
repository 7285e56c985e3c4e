// Zero images whose memory is touched only where they are written, for the full-scan masks of an edit that
// changes a small part of a large station (a cut's object in a 100 M-ray scan).
#pragma once

#include <opencv2/core.hpp>

namespace lidarshop {

// A zero-filled rows x cols matrix of `type` whose buffer comes from calloc: a large buffer is fresh pages
// the kernel maps (zeroed) on first write, so a mask written only in a window costs the window's pages, not
// the scan's. cv::Mat::zeros writes every byte, which on the machines we run on is what a 100 MB mask costs
// most (the first touch of fresh memory, about 3.5 s a GiB, docs/memory.md). Reading untouched cells reads
// zeros (on kernels that map their zero page for it, without memory; the Firecracker VMs we run on give a
// read fault a page of its own, so a mask read whole costs it whole there). The matrix behaves as any other
// (copies share it; clone() and operations allocate ordinary buffers).
cv::Mat LazyZeros(int rows, int cols, int type);

// A copy of an image that is zero outside `box` (strokes, a painted hole): a LazyZeros matrix with the box
// copied, so the copy costs the box's pages and reads nothing else.
cv::Mat CopyOfBox(const cv::Mat& image, const cv::Rect& box);

// The box of the non-zero cells of `mask` that lie in `within` (clipped to the mask; empty when none): the
// bounding box of a station's mask whose cells are known to lie in `within`, reading only that.
cv::Rect NonZeroBoxWithin(const cv::Mat& mask, const cv::Rect& within);

// The same when the box is not known: every row that holds a non-zero value is copied (the whole image is
// read).
cv::Mat CopyOfMostlyZero(const cv::Mat& image);

}  // namespace lidarshop
