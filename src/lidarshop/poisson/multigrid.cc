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
  std::vector<std::array<int, 2>> coarse_of_fine;    // per fine index
  std::vector<std::array<float, 2>> weight_of_fine;  // per fine index
  // The transpose: per coarse index, up to 4 fine indices and weights that prolong from it (unused entries
  // have weight 0 and a valid index).
  std::vector<std::array<int, 4>> fine_of_coarse;
  std::vector<std::array<float, 4>> fine_weight_of_coarse;
};

Transfer1D MakeTransfer(int fine_count, int coarse_count) {
  Transfer1D t;
  t.coarse_of_fine.resize(fine_count);
  t.weight_of_fine.resize(fine_count);
  std::vector<std::vector<std::pair<int, double>>> transpose(coarse_count);
  for (int f = 0; f < fine_count; ++f) {
    const int own = f / 2;
    int other = (f % 2 == 0) ? own - 1 : own + 1;
    other = std::clamp(other, 0, coarse_count - 1);
    t.coarse_of_fine[f] = {own, other};
    t.weight_of_fine[f] = {0.75f, 0.25f};
    transpose[own].push_back({f, 0.75});
    transpose[other].push_back({f, 0.25});
  }
  t.fine_of_coarse.resize(coarse_count);
  t.fine_weight_of_coarse.resize(coarse_count);
  for (int c = 0; c < coarse_count; ++c) {
    LIDARSHOP_CHECK(transpose[c].size() <= 4);
    for (int k = 0; k < 4; ++k) {
      const bool used = k < static_cast<int>(transpose[c].size());
      t.fine_of_coarse[c][k] = used ? transpose[c][k].first : transpose[c][0].first;
      t.fine_weight_of_coarse[c][k] = used ? static_cast<float>(transpose[c][k].second) : 0.0f;
    }
  }
  return t;
}

}  // namespace

struct MaskedMultigrid::Level {
  int rows = 0, cols = 0;
  int64_t stride = 0;  // cols + 2 (a ring of outside cells around the grid)
  std::vector<uint8_t> type;
  std::vector<uint8_t> degree;  // in-image neighbour count of unknown cells (the diagonal of A), 0 elsewhere
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
    degree.assign(Size(), 0);
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
        degree[i] = static_cast<uint8_t>((type[i - 1] != kOutside) + (type[i + 1] != kOutside) +
                                         (type[i - stride] != kOutside) + (type[i + stride] != kOutside));
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

// 1 / degree (a cell with no in-image neighbour cannot be unknown in a valid system, its entry is unused).
constexpr float kInverseDegree[5] = {0.0f, 1.0f, 0.5f, 1.0f / 3.0f, 0.25f};

// Calls op(row_base, columns, count) for every row of a level and colour(s), rows in parallel.
template <typename Op>
void ForRows(const Level& level, int first_colour, int last_colour, Op op) {
  ParallelForRange(
      level.rows,
      [&](int64_t y_begin, int64_t y_end) {
        for (int64_t y = y_begin; y < y_end; ++y) {
          const int64_t row_base = (y + 1) * level.stride + 1;
          for (int colour = first_colour; colour <= last_colour; ++colour) {
            const int64_t begin = level.row_begin[colour][y];
            op(y, row_base, level.columns[colour].data() + begin, level.row_begin[colour][y + 1] - begin);
          }
        }
      },
      kRowGrain);
}

// One Gauss–Seidel half sweep over the cells of one colour ((y + x) % 2): x = (b + sum of
// neighbours) / degree. Cells of one colour only read cells of the other, so rows run in
// parallel and the result is order-free.
void Sweep(const Level& level, int colour, const float* b, float* x) {
  const int64_t stride = level.stride;
  const uint8_t* degree = level.degree.data();
  ForRows(level, colour, colour, [&](int64_t, int64_t row_base, const int32_t* cols, int64_t count) {
    for (int64_t k = 0; k < count; ++k) {
      const int64_t i = row_base + cols[k];
      x[i] = (b[i] + x[i - 1] + x[i + 1] + x[i - stride] + x[i + stride]) * kInverseDegree[degree[i]];
    }
  });
}

// r = b − A x on unknown cells (other cells of r stay 0).
void Residual(const Level& level, const float* b, const float* x, float* r) {
  const int64_t stride = level.stride;
  const uint8_t* degree = level.degree.data();
  ForRows(level, 0, 1, [&](int64_t, int64_t row_base, const int32_t* cols, int64_t count) {
    for (int64_t k = 0; k < count; ++k) {
      const int64_t i = row_base + cols[k];
      r[i] = b[i] - (degree[i] * x[i] - x[i - 1] - x[i + 1] - x[i - stride] - x[i + stride]);
    }
  });
}

// coarse_b = P^T fine_r on the unknown cells of the coarse level.
void Restrict(const Level& fine, const Level& coarse, const float* fine_r, float* coarse_b) {
  ForRows(coarse, 0, 1, [&](int64_t y, int64_t row_base, const int32_t* cols, int64_t count) {
    const auto& fy = fine.transfer_y.fine_of_coarse[y];
    const auto& wy = fine.transfer_y.fine_weight_of_coarse[y];
    const float* rows[4];
    for (int j = 0; j < 4; ++j) rows[j] = fine_r + (fy[j] + 1) * fine.stride + 1;
    for (int64_t k = 0; k < count; ++k) {
      const int x = cols[k];
      const auto& fx = fine.transfer_x.fine_of_coarse[x];
      const auto& wx = fine.transfer_x.fine_weight_of_coarse[x];
      float sum = 0.0f;
      for (int j = 0; j < 4; ++j) {
        sum += wy[j] * (wx[0] * rows[j][fx[0]] + wx[1] * rows[j][fx[1]] + wx[2] * rows[j][fx[2]] +
                        wx[3] * rows[j][fx[3]]);
      }
      coarse_b[row_base + x] = sum;
    }
  });
}

// fine_x += P coarse_x on the unknown cells of the fine level.
void ProlongAdd(const Level& fine, const Level& coarse, const float* coarse_x, float* fine_x) {
  ForRows(fine, 0, 1, [&](int64_t y, int64_t row_base, const int32_t* cols, int64_t count) {
    const auto& cy = fine.transfer_y.coarse_of_fine[y];
    const auto& wy = fine.transfer_y.weight_of_fine[y];
    const float* row0 = coarse_x + (cy[0] + 1) * coarse.stride + 1;
    const float* row1 = coarse_x + (cy[1] + 1) * coarse.stride + 1;
    for (int64_t k = 0; k < count; ++k) {
      const int x = cols[k];
      const auto& cx = fine.transfer_x.coarse_of_fine[x];
      const auto& wx = fine.transfer_x.weight_of_fine[x];
      fine_x[row_base + x] += wy[0] * (wx[0] * row0[cx[0]] + wx[1] * row0[cx[1]]) +
                              wy[1] * (wx[0] * row1[cx[0]] + wx[1] * row1[cx[1]]);
    }
  });
}

// Runs op(i) on every unknown cell of a level and returns the sum of its results; per-row partial sums are
// added in row order, so the total does not depend on the thread count.
template <typename Op>
double SumOverUnknowns(const Level& level, Op op) {
  std::vector<double> partial(level.rows, 0.0);
  ForRows(level, 0, 1, [&](int64_t y, int64_t row_base, const int32_t* cols, int64_t count) {
    double sum = 0.0;
    for (int64_t k = 0; k < count; ++k) sum += op(row_base + cols[k]);
    partial[y] += sum;
  });
  double total = 0.0;
  for (double value : partial) total += value;
  return total;
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
    triplets.emplace_back(k, k, static_cast<double>(last.degree[i]));
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
  const int64_t stride = fine.stride;
  const uint8_t* degree = fine.degree.data();
  // The V-cycle runs in single precision (it only preconditions); CG runs in double.
  std::vector<std::vector<float>> xs(num_levels), bs(num_levels), rs(num_levels);
  for (int l = 0; l < num_levels; ++l) {
    xs[l].assign(levels_[l]->Size(), 0.0f);
    bs[l].assign(levels_[l]->Size(), 0.0f);
    rs[l].assign(levels_[l]->Size(), 0.0f);
  }
  std::vector<double> x(fine.Size(), 0.0), r(fine.Size(), 0.0), z(fine.Size(), 0.0), p(fine.Size(), 0.0),
      q(fine.Size(), 0.0);

  Eigen::VectorXd coarse_b(static_cast<Eigen::Index>(coarsest_->cells.size()));
  const int sweeps = options_.smoothing_sweeps;
  // z = V-cycle(r); returns r · z.
  auto v_cycle = [&]() {
    ForRows(fine, 0, 1, [&](int64_t, int64_t row_base, const int32_t* cols, int64_t count) {
      for (int64_t k = 0; k < count; ++k)
        bs[0][row_base + cols[k]] = static_cast<float>(r[row_base + cols[k]]);
    });
    for (int l = 0; l < num_levels; ++l) {
      const Level& level = *levels_[l];
      std::fill(xs[l].begin(), xs[l].end(), 0.0f);
      if (l == num_levels - 1) {
        for (size_t k = 0; k < coarsest_->cells.size(); ++k) coarse_b[k] = bs[l][coarsest_->cells[k]];
        const Eigen::VectorXd solution = coarsest_->factorization.solve(coarse_b);
        for (size_t k = 0; k < coarsest_->cells.size(); ++k) {
          xs[l][coarsest_->cells[k]] = static_cast<float>(solution[k]);
        }
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
    return SumOverUnknowns(fine, [&](int64_t i) {
      z[i] = xs[0][i];
      return r[i] * z[i];
    });
  };

  for (size_t k = 0; k < compact_to_grid_.size(); ++k) r[compact_to_grid_[k]] = b_compact[k];
  MultigridStats stats;
  const double b_norm = std::sqrt(SumOverUnknowns(fine, [&](int64_t i) { return r[i] * r[i]; }));
  x_compact.assign(compact_to_grid_.size(), 0.0);
  if (b_norm == 0.0) {
    stats.converged = true;
    return stats;
  }
  double rz = v_cycle();
  p = z;
  double r_norm = b_norm;
  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    // q = A p and p · q in one pass.
    const double pq = SumOverUnknowns(fine, [&](int64_t i) {
      q[i] = degree[i] * p[i] - p[i - 1] - p[i + 1] - p[i - stride] - p[i + stride];
      return p[i] * q[i];
    });
    const double alpha = rz / pq;
    // x += alpha p, r −= alpha q and r · r in one pass.
    r_norm = std::sqrt(SumOverUnknowns(fine, [&](int64_t i) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      return r[i] * r[i];
    }));
    stats.iterations = iteration;
    if (r_norm <= options_.tolerance * b_norm) {
      stats.converged = true;
      break;
    }
    const double rz_new = v_cycle();
    const double beta = rz_new / rz;
    rz = rz_new;
    SumOverUnknowns(fine, [&](int64_t i) {
      p[i] = z[i] + beta * p[i];
      return 0.0;
    });
  }
  stats.relative_residual = r_norm / b_norm;
  for (size_t k = 0; k < compact_to_grid_.size(); ++k) x_compact[k] = x[compact_to_grid_[k]];
  return stats;
}

}  // namespace lidarshop::poisson_internal
