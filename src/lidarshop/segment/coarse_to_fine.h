// Coarse to fine (SegmentOptions::coarse_max_cells): the level a large scan is cut on, the strokes and masks
// carried between it and full resolution, and the full-resolution cut of the band around the level's outline.
// Internal to the segment module.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"

namespace lidarshop::segment_internal {

struct ScanStats;  // segment_graph.h

// The smallest power of two f with ceil(rows/f) · ceil(cols/f) <= max_cells (1 when max_cells is 0 or the
// scan already fits).
int CoarseFactor(int rows, int cols, int64_t max_cells);

// Stroke labels (kStroke*) of the level whose cells are `level_cells` (DecimatedCells): a coarse cell takes
// the label of a stroked cell of its block when its own cell (the block's representative) has a return on
// the same surface — within kStrokeSurfaceFraction of that cell's range — so that a stroke along an object's
// edge does not label the level cell of what lies behind or before it; background when the block holds
// both (a background stroke is the user's word that something is not the object).
constexpr double kStrokeSurfaceFraction = 0.02;
cv::Mat CoarseStrokes(const Scan& scan, const cv::Mat& level_cells, const cv::Mat& strokes, int factor);

// One stroked cell: its index in the scan (row · cols + col) and its kStroke* label.
struct StrokeCell {
  int64_t cell = 0;
  uint8_t label = 0;
};
// The stroked cells of `strokes`, row by row.
std::vector<StrokeCell> StrokeCells(const cv::Mat& strokes);
// CoarseStrokes of the strokes `cells` (in row-major order): what a refinement adds, without an image of the
// station's size.
cv::Mat CoarseStrokes(const Scan& scan, const cv::Mat& level_cells, const std::vector<StrokeCell>& cells,
                      int factor);

// A mask of the level (CV_8U) at full resolution (`full` = rows x cols): every cell takes its block's value.
cv::Mat FullResolution(const cv::Mat& coarse_mask, int factor, cv::Size full);
// FullResolution(coarse_mask, factor, valid.size()) & (valid != 0), written only where the level's mask is
// set (LazyZeros): a mask of a large station costs the memory of its object's blocks.
cv::Mat FullResolutionWithReturns(const cv::Mat& coarse_mask, int factor, const cv::Mat& valid);

// Coarse cells within this many cells of the level's outline are cut again at full resolution.
constexpr int kBandCoarseCells = 2;

// A level is at most this much coarser than the scan it comes from; a scan that needs more goes down a
// pyramid (its level is cut coarse to fine in turn), so that each band re-cut is a few rays wide, not
// 2·kBandCoarseCells·f (at 100 M rays f is 16).
constexpr int kMaxLevelStep = 4;

// The object at full resolution from the level's cut `coarse_mask`: the cells deeper inside than the band are
// object, those farther outside background, and the band between is one colour-dominant cut (the depth cut's
// weights when the scan has neither colour nor intensity) on the full-resolution cells, its models learnt
// from the level's object and from its surroundings (within four bands), every cell of `strokes` (full
// resolution, kStroke*) a hard label; a stroke that contradicts the level (a background stroke inside, an
// object stroke outside) frees the cells within the band's width around it. `coarse_cells` is
// DecimatedCells(scan, factor). Keeps the 4-connected parts of the result that hold an inside cell or an
// object stroke. Adds its times to result->timings and sets result->graph_nodes, result->flow and
// result->object_box (the window it cut in). CV_8U 255/0, the scan's size, written only in that window
// (LazyZeros).
cv::Mat CutOutlineAtFullResolution(const Scan& scan, const ScanStats& stats, const cv::Mat& coarse_mask,
                                   const cv::Mat& coarse_cells, int factor, const cv::Mat& strokes,
                                   const SegmentOptions& options, bool has_appearance, SegmentResult* result);

}  // namespace lidarshop::segment_internal
