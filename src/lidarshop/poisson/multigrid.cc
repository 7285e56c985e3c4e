#include "lidarshop/poisson/multigrid.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <opencv2/imgproc.hpp>

#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop::poisson_internal {
namespace {

enum CellType : uint8_t { kOutside = 0, kKnown = 1, kUnknown = 2 };

constexpr int64_t kRowGrain = 8;

// Prolongation in one dimension: fine index f takes 3/4 of its own coarse cell and 1/4 of the nearer
// neighbouring coarse cell (clamped to the grid, which gives 1 at the edge).
struct Transfer1D {
  std::vector<std::array<int, 2>> coarse_of_fine;     // per fine index
  std::vector<std::array<double, 2>> weight_of_fine;  // per fine index
  // The transpose: per coarse index, the fine indices and weights that prolong from it.
  std::vector<std::vector<std::pair<int, double>>> fine_of_coarse;
};

Transfer1D MakeTransfer(int fine_count, int coarse_count) {
  Transfer1D t;
  t.coarse_of_fine.resize(fine_count);
  t.weight_of_fine.resize(fine_count);
  t.fine_of_coarse.resize(coarse_count);
  for (int f = 0; f < fine_count; ++f) {
    const int own = f / 2;
    int other = (f % 2 == 0) ? own - 1 : own + 1;
    other = std::clamp(other, 0, coarse_count - 1);
    t.coarse_of_fine[f] = {own, other};
    t.weight_of_fine[f] = {0.75, 0.25};
    t.fine_of_coarse[own].push_back({f, 0.75});
    t.fine_of_coarse[other].push_back({f, 0.25});
  }
  return t;
}

}  // namespace

struct MaskedMultigrid::Level {
  int rows = 0, cols = 0;
  int64_t stride = 0;  // cols + 2 (a ring of outside cells around the grid)
  std::vector<uint8_t> type;
  std::vector<double> diag;      // in-image neighbour count of unknown cells
  std::vector<double> inv_diag;  // 1 / diag, 0 elsewhere
  // Unknown columns per row and colour ((y + x) % 2): columns of row y, colour c are
  // columns[c][row_begin[c][y] .. row_begin[c][y + 1]).
  std::array<std::vector<int32_t>, 2> columns;
  std::array<std::vector<int64_t>, 2> row_begin;
  int64_t num_unknowns = 0;
  // To the next coarser level (empty on the coarsest):
  Transfer1D transfer_x, transfer_y;

  int64_t Index(int y, int x) const { return (y + 1) * stride + (x + 1); }
  int64_t Size() const { return (rows + 2) * stride; }

  void Finish() {
    stride = cols + 2;
    diag.assign(Size(), 0.0);
    inv_diag.assign(Size(), 0.0);
    num_unknowns = 0;
    for (int c = 0; c < 2; ++c) {
      columns[c].clear();
      row_begin[c].assign(rows + 1, 0);
    }
    for (int y = 0; y < rows; ++y) {
      for (int c = 0; c < 2; ++c) row_begin[c][y] = static_cast<int64_t>(columns[c].size());
      for (int x = 0; x < cols; ++x) {
        const int64_t i = Index(y, x);
        if (type[i] != kUnknown) continue;
        const int degree = (type[i - 1] != kOutside) + (type[i + 1] != kOutside) +
                           (type[i - stride] != kOutside) + (type[i + stride] != kOutside);
        diag[i] = degree;
        inv_diag[i] = degree > 0 ? 1.0 / degree : 0.0;
        columns[(y + x) % 2].push_back(x);
        ++num_unknowns;
      }
    }
    for (int c = 0; c < 2; ++c) row_begin[c][rows] = static_cast<int64_t>(columns[c].size());
  }
};

struct MaskedMultigrid::Coarsest {
  std::vector<int64_t> cells;  // memory indices of the unknowns of the coarsest level
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factorization;
};

namespace {

using Level = MaskedMultigrid::Level;

// One Gauss–Seidel half sweep over the cells of one colour: x = (b + sum of neighbours) / diag.
void Sweep(const Level& level, int colour, const double* b, double* x) {
  const int64_t stride = level.stride;
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int32_t* cols = level.columns[colour].data();  // colour = (y + x) % 2
          const int64_t row_base = (y + 1) * stride + 1;
          for (int64_t k = level.row_begin[colour][y]; k < level.row_begin[colour][y + 1]; ++k) {
            const int64_t i = row_base + cols[k];
            x[i] = (b[i] + x[i - 1] + x[i + 1] + x[i - stride] + x[i + stride]) * level.inv_diag[i];
          }
        }
      },
      kRowGrain);
}

// r = b − A x on unknown cells (other cells of r are left at 0).
void Residual(const Level& level, const double* b, const double* x, double* r) {
  const int64_t stride = level.stride;
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * stride + 1;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = level.columns[colour].data();
            for (int64_t k = level.row_begin[colour][y]; k < level.row_begin[colour][y + 1]; ++k) {
              const int64_t i = row_base + cols[k];
              r[i] = b[i] - (level.diag[i] * x[i] - x[i - 1] - x[i + 1] - x[i - stride] - x[i + stride]);
            }
          }
        }
      },
      kRowGrain);
}

// q = A p on unknown cells.
void Apply(const Level& level, const double* p, double* q) {
  const int64_t stride = level.stride;
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * stride + 1;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = level.columns[colour].data();
            for (int64_t k = level.row_begin[colour][y]; k < level.row_begin[colour][y + 1]; ++k) {
              const int64_t i = row_base + cols[k];
              q[i] = level.diag[i] * p[i] - p[i - 1] - p[i + 1] - p[i - stride] - p[i + stride];
            }
          }
        }
      },
      kRowGrain);
}

// coarse_b = P^T fine_r on the unknown cells of the coarse level.
void Restrict(const Level& fine, const Level& coarse, const double* fine_r, double* coarse_b) {
  ParallelForRange(
      coarse.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * coarse.stride + 1;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = coarse.columns[colour].data();
            for (int64_t k = coarse.row_begin[colour][y]; k < coarse.row_begin[colour][y + 1]; ++k) {
              const int x = cols[k];
              double sum = 0.0;
              for (const auto& [fy, wy] : fine.transfer_y.fine_of_coarse[y]) {
                const double* fine_row = fine_r + (fy + 1) * fine.stride + 1;
                double row_sum = 0.0;
                for (const auto& [fx, wx] : fine.transfer_x.fine_of_coarse[x]) row_sum += wx * fine_row[fx];
                sum += wy * row_sum;
              }
              coarse_b[row_base + x] = sum;
            }
          }
        }
      },
      kRowGrain);
}

// fine_x += P coarse_x on the unknown cells of the fine level.
void ProlongAdd(const Level& fine, const Level& coarse, const double* coarse_x, double* fine_x) {
  ParallelForRange(
      fine.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const auto& cy = fine.transfer_y.coarse_of_fine[y];
          const auto& wy = fine.transfer_y.weight_of_fine[y];
          const double* row0 = coarse_x + (cy[0] + 1) * coarse.stride + 1;
          const double* row1 = coarse_x + (cy[1] + 1) * coarse.stride + 1;
          const int64_t row_base = (y + 1) * fine.stride + 1;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = fine.columns[colour].data();
            for (int64_t k = fine.row_begin[colour][y]; k < fine.row_begin[colour][y + 1]; ++k) {
              const int x = cols[k];
              const auto& cx = fine.transfer_x.coarse_of_fine[x];
              const auto& wx = fine.transfer_x.weight_of_fine[x];
              fine_x[row_base + x] += wy[0] * (wx[0] * row0[cx[0]] + wx[1] * row0[cx[1]]) +
                                      wy[1] * (wx[0] * row1[cx[0]] + wx[1] * row1[cx[1]]);
            }
          }
        }
      },
      kRowGrain);
}

// Deterministic dot product over a level's unknown cells: per-row partials summed in row order.
double Dot(const Level& level, const double* a, const double* b) {
  std::vector<double> partial(level.rows, 0.0);
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * level.stride + 1;
          double sum = 0.0;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = level.columns[colour].data();
            for (int64_t k = level.row_begin[colour][y]; k < level.row_begin[colour][y + 1]; ++k) {
              const int64_t i = row_base + cols[k];
              sum += a[i] * b[i];
            }
          }
          partial[y] = sum;
        }
      },
      kRowGrain);
  double total = 0.0;
  for (double value : partial) total += value;
  return total;
}

// y = a * x + y (axpy) or y = x + beta * y (when scale_y), on a level's unknown cells.
template <typename Op>
void ForUnknowns(const Level& level, Op op) {
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * level.stride + 1;
          for (int colour = 0; colour < 2; ++colour) {
            const int32_t* cols = level.columns[colour].data();
            for (int64_t k = level.row_begin[colour][y]; k < level.row_begin[colour][y + 1]; ++k) {
              op(row_base + cols[k]);
            }
          }
        }
      },
      kRowGrain);
}

}  // namespace

MaskedMultigrid::MaskedMultigrid(const cv::Mat& mask, const PoissonOptions& options) : options_(options) {
  LIDARSHOP_CHECK(mask.type() == CV_8UC1);
  const cv::Rect box = cv::boundingRect(mask);
  LIDARSHOP_CHECK(box.area() > 0);
  // The bounding box plus a 1-pixel ring of (known) neighbours, clipped to the image.
  const cv::Rect grid_box =
      cv::Rect(box.x - 1, box.y - 1, box.width + 2, box.height + 2) & cv::Rect(0, 0, mask.cols, mask.rows);

  auto level0 = std::make_unique<Level>();
  level0->rows = grid_box.height;
  level0->cols = grid_box.width;
  level0->stride = level0->cols + 2;
  level0->type.assign(level0->Size(), kOutside);
  for (int y = 0; y < grid_box.height; ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(grid_box.y + y) + grid_box.x;
    for (int x = 0; x < grid_box.width; ++x) level0->type[level0->Index(y, x)] = row[x] ? kUnknown : kKnown;
  }
  level0->Finish();
  // Compact order is row-major over the image, which is row-major over the grid.
  compact_to_grid_.reserve(level0->num_unknowns);
  for (int y = 0; y < level0->rows; ++y) {
    for (int x = 0; x < level0->cols; ++x) {
      if (level0->type[level0->Index(y, x)] == kUnknown) compact_to_grid_.push_back(level0->Index(y, x));
    }
  }
  levels_.push_back(std::move(level0));

  while (static_cast<int>(levels_.size()) < options.max_levels) {
    Level& fine = *levels_.back();
    if (fine.num_unknowns <= options.coarsest_max_unknowns || fine.rows < 3 || fine.cols < 3) break;
    auto coarse = std::make_unique<Level>();
    coarse->rows = (fine.rows + 1) / 2;
    coarse->cols = (fine.cols + 1) / 2;
    coarse->stride = coarse->cols + 2;
    coarse->type.assign(coarse->Size(), kOutside);
    for (int y = 0; y < coarse->rows; ++y) {
      for (int x = 0; x < coarse->cols; ++x) {
        bool any_known = false, any_unknown = false;
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            const int fy = 2 * y + dy, fx = 2 * x + dx;
            if (fy >= fine.rows || fx >= fine.cols) continue;
            const uint8_t t = fine.type[fine.Index(fy, fx)];
            any_known |= t == kKnown;
            any_unknown |= t == kUnknown;
          }
        }
        coarse->type[coarse->Index(y, x)] = any_known ? kKnown : (any_unknown ? kUnknown : kOutside);
      }
    }
    coarse->Finish();
    if (coarse->num_unknowns == 0) break;
    fine.transfer_x = MakeTransfer(fine.cols, coarse->cols);
    fine.transfer_y = MakeTransfer(fine.rows, coarse->rows);
    levels_.push_back(std::move(coarse));
  }

  // Direct factorization of the coarsest level.
  const Level& last = *levels_.back();
  coarsest_ = std::make_unique<Coarsest>();
  std::vector<int64_t> compact(last.Size(), -1);
  for (int y = 0; y < last.rows; ++y) {
    for (int x = 0; x < last.cols; ++x) {
      const int64_t i = last.Index(y, x);
      if (last.type[i] != kUnknown) continue;
      compact[i] = static_cast<int64_t>(coarsest_->cells.size());
      coarsest_->cells.push_back(i);
    }
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t k = 0; k < coarsest_->cells.size(); ++k) {
    const int64_t i = coarsest_->cells[k];
    triplets.emplace_back(k, k, last.diag[i]);
    for (int64_t n : {i - 1, i + 1, i - last.stride, i + last.stride}) {
      if (compact[n] >= 0) triplets.emplace_back(k, compact[n], -1.0);
    }
  }
  const auto n = static_cast<Eigen::Index>(coarsest_->cells.size());
  Eigen::SparseMatrix<double> matrix(n, n);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  coarsest_->factorization.compute(matrix);
  LIDARSHOP_CHECK(coarsest_->factorization.info() == Eigen::Success);
}

MaskedMultigrid::~MaskedMultigrid() = default;

int MaskedMultigrid::NumLevels() const { return static_cast<int>(levels_.size()); }

MultigridStats MaskedMultigrid::Solve(const std::vector<double>& b_compact,
                                      std::vector<double>& x_compact) const {
  LIDARSHOP_CHECK(b_compact.size() == compact_to_grid_.size());
  const int num_levels = NumLevels();
  const Level& fine = *levels_[0];
  // Work arrays: per level x, b, r (level 0's b and x are the CG residual and preconditioned residual).
  std::vector<std::vector<double>> xs(num_levels), bs(num_levels), rs(num_levels);
  for (int l = 0; l < num_levels; ++l) {
    xs[l].assign(levels_[l]->Size(), 0.0);
    bs[l].assign(levels_[l]->Size(), 0.0);
    rs[l].assign(levels_[l]->Size(), 0.0);
  }
  std::vector<double> x(fine.Size(), 0.0), r(fine.Size(), 0.0), p(fine.Size(), 0.0), q(fine.Size(), 0.0);

  Eigen::VectorXd coarse_b(static_cast<Eigen::Index>(coarsest_->cells.size()));
  const int sweeps = options_.smoothing_sweeps;
  // z = V-cycle(r): writes xs[0].
  auto v_cycle = [&](const double* residual) {
    std::copy(residual, residual + fine.Size(), bs[0].begin());
    for (int l = 0; l < num_levels; ++l) {
      const Level& level = *levels_[l];
      std::fill(xs[l].begin(), xs[l].end(), 0.0);
      if (l == num_levels - 1) {
        for (size_t k = 0; k < coarsest_->cells.size(); ++k) coarse_b[k] = bs[l][coarsest_->cells[k]];
        const Eigen::VectorXd solution = coarsest_->factorization.solve(coarse_b);
        for (size_t k = 0; k < coarsest_->cells.size(); ++k) xs[l][coarsest_->cells[k]] = solution[k];
        break;
      }
      for (int s = 0; s < sweeps; ++s) {
        Sweep(level, 0, bs[l].data(), xs[l].data());
        Sweep(level, 1, bs[l].data(), xs[l].data());
      }
      Residual(level, bs[l].data(), xs[l].data(), rs[l].data());
      Restrict(level, *levels_[l + 1], rs[l].data(), bs[l + 1].data());
    }
    for (int l = num_levels - 2; l >= 0; --l) {
      const Level& level = *levels_[l];
      ProlongAdd(level, *levels_[l + 1], xs[l + 1].data(), xs[l].data());
      for (int s = 0; s < sweeps; ++s) {
        Sweep(level, 1, bs[l].data(), xs[l].data());
        Sweep(level, 0, bs[l].data(), xs[l].data());
      }
    }
  };

  for (size_t k = 0; k < compact_to_grid_.size(); ++k) r[compact_to_grid_[k]] = b_compact[k];
  MultigridStats stats;
  const double b_norm = std::sqrt(Dot(fine, r.data(), r.data()));
  x_compact.assign(compact_to_grid_.size(), 0.0);
  if (b_norm == 0.0) {
    stats.converged = true;
    return stats;
  }
  v_cycle(r.data());
  std::vector<double>& z = xs[0];
  std::copy(z.begin(), z.end(), p.begin());
  double rz = Dot(fine, r.data(), z.data());
  double r_norm = b_norm;
  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    Apply(fine, p.data(), q.data());
    const double alpha = rz / Dot(fine, p.data(), q.data());
    ForUnknowns(fine, [&](int64_t i) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    });
    r_norm = std::sqrt(Dot(fine, r.data(), r.data()));
    stats.iterations = iteration;
    if (r_norm <= options_.tolerance * b_norm) {
      stats.converged = true;
      break;
    }
    v_cycle(r.data());
    const double rz_new = Dot(fine, r.data(), z.data());
    const double beta = rz_new / rz;
    rz = rz_new;
    ForUnknowns(fine, [&](int64_t i) { p[i] = z[i] + beta * p[i]; });
  }
  stats.relative_residual = r_norm / b_norm;
  for (size_t k = 0; k < compact_to_grid_.size(); ++k) x_compact[k] = x[compact_to_grid_[k]];
  return stats;
}

}  // namespace lidarshop::poisson_internal
