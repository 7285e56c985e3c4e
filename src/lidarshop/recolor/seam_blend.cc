#include "lidarshop/recolor/seam_blend.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <vector>

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

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
  const int rows = photo.rows, cols = photo.cols;
  SeamBlendResult result;
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
  const SeamBandSolution band = SolveSeamBand(
      photo, band_cells, [&](int64_t cell) { return colour.at<cv::Vec3f>(cell / cols, cell % cols); },
      [&](int64_t cell, bool down) {
        return (down ? gy : gx).at<cv::Vec3f>(static_cast<int>(cell / cols), static_cast<int>(cell % cols));
      });
  result.seam_edges = band.seam_edges;
  result.unknowns = static_cast<int64_t>(band.cells.size());
  result.seconds = band.seconds;
  result.colour = colour;
  if (band.cells.empty()) return result;
  result.colour = colour.clone();
  for (size_t k = 0; k < band.cells.size(); ++k)
    result.colour.at<cv::Vec3f>(static_cast<int>(band.cells[k] / cols),
                                static_cast<int>(band.cells[k] % cols)) = band.colour[k];
  return result;
}

SeamBandSolution SolveSeamBand(const cv::Mat& photo, int band_cells, const SeamCellColour& colour_of,
                               const SeamEdgeGuidance& guidance) {
  if (photo.type() != CV_16U || photo.empty())
    ThrowInputError("SolveSeamBand", "", "photo", "expected CV_16U");
  if (band_cells < 1)
    ThrowInputError("SolveSeamBand", "", "band_cells", fmt::format("must be >= 1, got {}", band_cells));
  const auto start = std::chrono::steady_clock::now();
  const int rows = photo.rows, cols = photo.cols;
  SeamBandSolution result;
  const auto coloured = [&](int r, int c) { return photo.at<uint16_t>(r, c) != 0; };
  // The seam cells: coloured, with a coloured 4-neighbour of another photo (rows in parallel, each writing
  // only its own row of the mask).
  cv::Mat seam(rows, cols, CV_8U);
  std::vector<int64_t> row_edges(rows, 0);
  ParallelFor(rows, [&](int64_t row) {
    const int r = static_cast<int>(row);
    const uint16_t* p = photo.ptr<uint16_t>(r);
    const uint16_t* above = r > 0 ? photo.ptr<uint16_t>(r - 1) : nullptr;
    const uint16_t* below = r + 1 < rows ? photo.ptr<uint16_t>(r + 1) : nullptr;
    uint8_t* out = seam.ptr<uint8_t>(r);
    for (int c = 0; c < cols; ++c) {
      out[c] = 0;
      if (p[c] == 0) continue;
      const auto differs = [&](uint16_t q) { return q != 0 && q != p[c]; };
      const bool right = c + 1 < cols && differs(p[c + 1]);
      const bool down = below != nullptr && differs(below[c]);
      row_edges[r] += static_cast<int>(right) + static_cast<int>(down);
      if (right || down || (c > 0 && differs(p[c - 1])) || (above != nullptr && differs(above[c])))
        out[c] = 255;
    }
  });
  for (const int64_t n : row_edges) result.seam_edges += n;
  const auto done = [&] {
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  if (result.seam_edges == 0) return done();

  // Ω's candidates: the coloured cells within the band, row-major (rows in parallel, joined in order).
  cv::Mat band;
  cv::dilate(seam, band,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * band_cells + 1, 2 * band_cells + 1)));
  std::vector<std::vector<int64_t>> row_cells(rows);
  ParallelFor(rows, [&](int64_t row) {
    const int r = static_cast<int>(row);
    const uint8_t* in_band = band.ptr<uint8_t>(r);
    const uint16_t* p = photo.ptr<uint16_t>(r);
    for (int c = 0; c < cols; ++c) {
      if (in_band[c] != 0 && p[c] != 0) row_cells[r].push_back(row * cols + c);
    }
  });
  std::vector<int64_t> cells;
  for (auto& list : row_cells) {
    cells.insert(cells.end(), list.begin(), list.end());
    std::vector<int64_t>().swap(list);
  }
  const auto index_in = [](const std::vector<int64_t>& list, int64_t cell) -> int64_t {
    const auto it = std::lower_bound(list.begin(), list.end(), cell);
    return it != list.end() && *it == cell ? it - list.begin() : -1;
  };
  // A part of the coloured cells with no cell outside the band would have no boundary: anchor its first cell.
  // Such a part is a 4-connected part of the candidates with no coloured neighbour outside the band (a
  // coloured part with a cell outside the band reaches one from each of its candidate parts).
  {
    const int64_t n = static_cast<int64_t>(cells.size());
    std::vector<int64_t> parent(n);
    for (int64_t k = 0; k < n; ++k) parent[k] = k;
    const auto find = [&](int64_t k) {
      while (parent[k] != k) k = parent[k] = parent[parent[k]];
      return k;
    };
    const auto join = [&](int64_t a, int64_t b) {  // the root is the part's first cell
      a = find(a), b = find(b);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    std::vector<char> has_known(n, 0);
    for (int64_t k = 0; k < n; ++k) {
      const int r = static_cast<int>(cells[k] / cols), c = static_cast<int>(cells[k] % cols);
      if (c + 1 < cols && k + 1 < n && cells[k + 1] == cells[k] + 1) join(k, k + 1);
      if (r + 1 < rows) {
        const int64_t below = index_in(cells, cells[k] + cols);
        if (below >= 0) join(k, below);
      }
    }
    for (int64_t k = 0; k < n; ++k) {
      const int r = static_cast<int>(cells[k] / cols), c = static_cast<int>(cells[k] % cols);
      const auto known = [&](int nr, int nc) {
        return nr >= 0 && nr < rows && nc >= 0 && nc < cols && coloured(nr, nc) &&
               band.at<uint8_t>(nr, nc) == 0;
      };
      if (known(r, c - 1) || known(r, c + 1) || known(r - 1, c) || known(r + 1, c)) has_known[find(k)] = 1;
    }
    std::vector<int64_t> unknowns;
    unknowns.reserve(n);
    for (int64_t k = 0; k < n; ++k) {
      if (find(k) == k && !has_known[k]) continue;  // the anchor keeps its colour
      unknowns.push_back(cells[k]);
    }
    cells.swap(unknowns);
  }
  result.cells = cells;
  const int64_t n = static_cast<int64_t>(cells.size());
  if (n == 0) return done();

  // The engine's equations for this Ω (poisson.cc: PreparePoisson, SolveChannels), unknowns and neighbours
  // in the same order, so the same matrix and right-hand sides to the bit: per unknown its left, right,
  // upper and lower neighbour, an edge to an uncoloured cell left out (no-data).
  std::vector<std::array<int64_t, 4>> neighbour(n);  // index in Ω, −1 known, −2 no edge
  std::vector<cv::Vec3f> divergence(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k) {
          const int64_t cell = cells[k];
          const int r = static_cast<int>(cell / cols), c = static_cast<int>(cell % cols);
          const int at[4][2] = {{r, c - 1}, {r, c + 1}, {r - 1, c}, {r + 1, c}};
          for (int e = 0; e < 4; ++e) {
            const int nr = at[e][0], nc = at[e][1];
            neighbour[k][e] = nr >= 0 && nr < rows && nc >= 0 && nc < cols && coloured(nr, nc)
                                  ? index_in(cells, static_cast<int64_t>(nr) * cols + nc)
                                  : -2;
          }
          // BackwardDivergence of the guidance (float, as the engine's operators.cc computes it).
          const cv::Vec3f zero(0, 0, 0);
          const cv::Vec3f right = neighbour[k][1] != -2 ? guidance(cell, false) : zero;
          const cv::Vec3f left = neighbour[k][0] != -2 ? guidance(cell - 1, false) : zero;
          const cv::Vec3f down = neighbour[k][3] != -2 ? guidance(cell, true) : zero;
          const cv::Vec3f up = neighbour[k][2] != -2 ? guidance(cell - cols, true) : zero;
          for (int ch = 0; ch < 3; ++ch) divergence[k][ch] = (right[ch] - left[ch]) + (down[ch] - up[ch]);
        }
      },
      4096);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(n) * 5);
  for (int64_t k = 0; k < n; ++k) {
    int degree = 0;
    for (const int64_t other : neighbour[k]) {
      if (other == -2) continue;
      ++degree;
      if (other >= 0) triplets.emplace_back(static_cast<int>(k), static_cast<int>(other), -1.0);
    }
    triplets.emplace_back(static_cast<int>(k), static_cast<int>(k), static_cast<double>(degree));
  }
  Eigen::SparseMatrix<double> matrix(n, n);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> factorization;
  factorization.compute(matrix);
  if (factorization.info() != Eigen::Success)
    throw std::runtime_error("SolveSeamBand: CHOLMOD factorization failed");
  // The known neighbours' colours, read once.
  std::vector<std::array<cv::Vec3f, 4>> known(n);
  ParallelForRange(
      n,
      [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k) {
          const int64_t cell = cells[k];
          const int64_t at[4] = {cell - 1, cell + 1, cell - cols, cell + cols};
          for (int e = 0; e < 4; ++e) {
            if (neighbour[k][e] == -1) known[k][e] = colour_of(at[e]);
          }
        }
      },
      4096);
  result.colour.resize(n);
  for (int ch = 0; ch < 3; ++ch) {
    Eigen::VectorXd b(n);
    for (int64_t k = 0; k < n; ++k) {
      double value = -static_cast<double>(divergence[k][ch]);
      for (int e = 0; e < 4; ++e) {
        if (neighbour[k][e] == -1) value += known[k][e][ch];
      }
      b[k] = value;
    }
    const Eigen::VectorXd x = factorization.solve(b);
    for (int64_t k = 0; k < n; ++k) result.colour[k][ch] = static_cast<float>(x[k]);
  }
  return done();
}

}  // namespace lidarshop
