#include "lidarshop/recolor/seam_blend.h"

#include <chrono>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/operators.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/error.h"

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
  check(colour, CV_64FC3, "colour");
  check(gx, CV_64FC3, "gx");
  check(gy, CV_64FC3, "gy");
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
  result.colour = colour.clone();
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

  // The guidance only between two coloured cells (edges to a cell without colour carry no flux).
  cv::Mat gx_linked = gx.clone(), gy_linked = gy.clone();
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const bool here = photo.at<uint16_t>(r, c) != 0;
      if (!here || c + 1 >= cols || photo.at<uint16_t>(r, c + 1) == 0) gx_linked.at<cv::Vec3d>(r, c) = {};
      if (!here || r + 1 >= rows || photo.at<uint16_t>(r + 1, c) == 0) gy_linked.at<cv::Vec3d>(r, c) = {};
    }
  }
  PoissonOptions options;
  options.solver = PoissonSolverKind::kDirect;  // no-data edges at Ω take the direct solver anyway
  PoissonLinks links;
  links.no_data = coloured == 0;
  const PoissonSystem system = PreparePoisson(band, options, links);
  cv::Mat boundary = colour.clone();
  boundary.setTo(cv::Scalar::all(0), links.no_data);
  result.colour = SolvePoisson(system, boundary, BackwardDivergence(gx_linked, gy_linked)).image;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace lidarshop
