#include "lidarshop/recolor/seam_blend.h"

#include <chrono>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/operators.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

SeamBlendResult BlendSeams(const cv::Mat& colour, const cv::Mat& photo, const cv::Mat& gx, const cv::Mat& gy,
                           int band_cells) {
  const auto check = [&](const cv::Mat& m, int type, const char* name) {
    if (m.type() != type || m.size() != photo.size())
      ThrowInputError("BlendSeams", "", name,
                      fmt::format("expected {} x {} of type {}, got {} x {} of type {}", photo.cols,
                                  photo.rows, type, m.cols, m.rows, m.type()));
  };
  if (photo.type() != CV_16U || photo.empty()) ThrowInputError("BlendSeams", "", "photo", "expected CV_16U");
  check(colour, CV_32FC3, "colour");
  check(gx, CV_32FC3, "gx");
  check(gy, CV_32FC3, "gy");
  if (band_cells < 1)
    ThrowInputError("BlendSeams", "", "band_cells", fmt::format("must be >= 1, got {}", band_cells));
  const auto start = std::chrono::steady_clock::now();
  const int rows = photo.rows, cols = photo.cols;
  SeamBlendResult result;
  const cv::Mat coloured = photo > 0;
  cv::Mat seam = cv::Mat::zeros(rows, cols, CV_8U);
  for (int r = 0; r < rows; ++r) {
    const uint16_t* p = photo.ptr<uint16_t>(r);
    const uint16_t* below = r + 1 < rows ? photo.ptr<uint16_t>(r + 1) : nullptr;
    for (int c = 0; c < cols; ++c) {
      if (p[c] == 0) continue;
      if (c + 1 < cols && p[c + 1] != 0 && p[c + 1] != p[c]) {
        seam.at<uint8_t>(r, c) = seam.at<uint8_t>(r, c + 1) = 255;
        ++result.seam_edges;
      }
      if (below != nullptr && below[c] != 0 && below[c] != p[c]) {
        seam.at<uint8_t>(r, c) = seam.at<uint8_t>(r + 1, c) = 255;
        ++result.seam_edges;
      }
    }
  }
  // The guidance must carry no flux out of the coloured cells (the caller's zeros, not copied: 10-megapoint
  // grids) and the cells without colour must hold 0 (they are the no-data boundary).
  // Rows in parallel (a 10-megapoint grid), then the first row with a fault checked again to name its cell.
  const auto check_row = [&](int r, bool report) {
    for (int c = 0; c < cols; ++c) {
      const bool here = photo.at<uint16_t>(r, c) != 0;
      const bool right = here && c + 1 < cols && photo.at<uint16_t>(r, c + 1) != 0;
      const bool down = here && r + 1 < rows && photo.at<uint16_t>(r + 1, c) != 0;
      if ((!right && gx.at<cv::Vec3f>(r, c) != cv::Vec3f()) ||
          (!down && gy.at<cv::Vec3f>(r, c) != cv::Vec3f())) {
        if (!report) return false;
        ThrowInputError("BlendSeams", fmt::format("cell ({}, {})", r, c), "gx/gy",
                        "guidance on an edge that does not join two coloured cells must be 0");
      }
      if (!here && colour.at<cv::Vec3f>(r, c) != cv::Vec3f()) {
        if (!report) return false;
        ThrowInputError("BlendSeams", fmt::format("cell ({}, {})", r, c), "colour",
                        "a cell without a photo must hold 0");
      }
    }
    return true;
  };
  std::vector<uint8_t> row_ok(rows, 1);
  ParallelFor(rows, [&](int64_t r) { row_ok[r] = check_row(static_cast<int>(r), false); });
  for (int r = 0; r < rows; ++r) {
    if (!row_ok[r]) check_row(r, true);  // throws, naming the first faulty cell
  }
  result.colour = colour;
  if (result.seam_edges == 0) return result;

  // Ω: the coloured cells within the band.
  cv::Mat band;
  cv::dilate(seam, band,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * band_cells + 1, 2 * band_cells + 1)));
  band &= coloured;
  // A part of the coloured cells with no cell outside the band would have no boundary: anchor its first cell.
  cv::Mat labels;
  const int parts = cv::connectedComponents(coloured, labels, 4, CV_32S);
  std::vector<char> has_known(parts, 0);
  std::vector<cv::Point> first(parts, cv::Point(-1, -1));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int label = labels.at<int>(r, c);
      if (label == 0) continue;
      if (first[label].x < 0) first[label] = cv::Point(c, r);
      if (!band.at<uint8_t>(r, c)) has_known[label] = 1;
    }
  }
  for (int label = 1; label < parts; ++label) {
    if (!has_known[label]) band.at<uint8_t>(first[label]) = 0;
  }
  result.unknowns = cv::countNonZero(band);
  if (result.unknowns == 0) return result;

  PoissonOptions options;
  options.solver = PoissonSolverKind::kDirect;  // no-data edges at Ω take the direct solver anyway
  PoissonLinks links;
  links.no_data = coloured == 0;
  const PoissonSystem system = PreparePoisson(band, options, links);
  result.colour = SolvePoisson(system, colour, BackwardDivergence(gx, gy)).image;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace lidarshop
