// Blending the seams of a scan coloured from several photos in the gradient domain (issue 32 item 3), on the
// scan's grid with the Poisson engine (poisson/poisson.h).
//
// Where the photo that colours a cell changes between 4-neighbours, a residual exposure or white-balance
// difference shows as a step. The cells within `band_cells` (Chebyshev distance) of such a seam become the
// unknowns Ω of a Poisson problem whose guidance field is given per edge (`gx`, `gy`: the colour difference
// the surface should have across the edge, taken from one photo that sees both cells); the coloured cells
// outside the band keep their colours and are the Dirichlet boundary, cells without a colour are no-data (no
// flux). The step is thus spread smoothly over the band (Pérez, Gangnet, Blake 2003; the "gradient-domain
// stitching" of panoramas). A connected part of the coloured cells lying wholly within the band has no
// boundary: its first cell in row-major order keeps its colour and anchors it.
//
// The work follows the band, not the grid (issue 32 item 6: a 10-megapoint station has ~90,000 band cells):
// SolveSeamBand finds Ω, assembles its equations and solves them from the band cells and their neighbours
// alone, reading colours and guidance through callbacks, so no grid-sized colour, guidance or divergence
// image is made. The equations are those the Poisson engine (poisson/poisson.h) would assemble for the band
// mask with the uncoloured cells as no-data, in the same order, factored by the same CHOLMOD supernodal
// Cholesky: the solution is the engine's to the bit (seam_blend_test compares them).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

namespace lidarshop {

struct SeamBlendResult {
  cv::Mat colour;  // rows x cols CV_32FC3: the input with the band replaced by the solution (unclamped)
  int64_t seam_edges = 0;  // 4-neighbour pairs of coloured cells whose photos differ
  int64_t unknowns = 0;    // cells solved for
  double seconds = 0;      // wall clock of the Poisson solve (preparation included)
};

// colour      rows x cols CV_32FC3: every coloured cell's colour (any units, e.g. RGB 0–255), 0 in the others;
// photo       rows x cols CV_16U: 1 + the photo that coloured the cell, 0 = no colour;
// gx, gy      rows x cols CV_32FC3: the guidance from a cell to its right / lower neighbour (as
//             poisson/operators.h lays out ForwardGradient); 0 on every edge that does not join two coloured
//             cells (no flux there; checked);
// band_cells  >= 1. Throws InputError when sizes or types differ.
SeamBlendResult BlendSeams(const cv::Mat& colour, const cv::Mat& photo, const cv::Mat& gx, const cv::Mat& gy,
                           int band_cells);

// The band's solution alone.
struct SeamBandSolution {
  std::vector<int64_t> cells;     // Ω, cell = row * cols + col, row-major
  std::vector<cv::Vec3f> colour;  // the solution at each of `cells`
  int64_t seam_edges = 0;         // as SeamBlendResult
  double seconds = 0;             // wall clock
};

// photo       rows x cols CV_16U as for BlendSeams;
// colour      the colour of a coloured cell (called for the cells next to Ω);
// guidance    the guidance from a coloured cell to its right (`down` false) or lower neighbour, called only
//             when that neighbour is coloured too (the edges of the cells of Ω);
// band_cells  >= 1. The callbacks may be called from several threads at once.
using SeamCellColour = std::function<cv::Vec3f(int64_t cell)>;
using SeamEdgeGuidance = std::function<cv::Vec3f(int64_t cell, bool down)>;
SeamBandSolution SolveSeamBand(const cv::Mat& photo, int band_cells, const SeamCellColour& colour,
                               const SeamEdgeGuidance& guidance);

}  // namespace lidarshop
