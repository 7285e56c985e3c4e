#include "lidarshop/poisson/poisson.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include <fmt/format.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <opencv2/imgproc.hpp>

#include "lidarshop/poisson/multigrid.h"
#include "lidarshop/poisson/operators.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

using poisson_internal::MaskedMultigrid;

void PoissonOptions::Check() const { Validate(*this); }

namespace {

// A factored sparse matrix; Solve may be called from several threads.
class DirectSolver {
 public:
  virtual ~DirectSolver() = default;
  virtual Eigen::VectorXd Solve(const Eigen::VectorXd& b) const = 0;
};

class CholmodSolver : public DirectSolver {
 public:
  explicit CholmodSolver(const Eigen::SparseMatrix<double>& matrix) {
    factorization_.compute(matrix);
    if (factorization_.info() != Eigen::Success) throw std::runtime_error("CHOLMOD factorization failed");
  }
  Eigen::VectorXd Solve(const Eigen::VectorXd& b) const override {
    std::lock_guard<std::mutex> lock(mutex_);  // CHOLMOD's workspace (cholmod_common) is shared
    return factorization_.solve(b);
  }

 private:
  mutable std::mutex mutex_;
  mutable Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> factorization_;
};

class EigenLdltSolver : public DirectSolver {
 public:
  explicit EigenLdltSolver(const Eigen::SparseMatrix<double>& matrix) {
    factorization_.compute(matrix);
    if (factorization_.info() != Eigen::Success)
      throw std::runtime_error("SimplicialLDLT factorization failed");
  }
  Eigen::VectorXd Solve(const Eigen::VectorXd& b) const override { return factorization_.solve(b); }

 private:
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factorization_;
};

cv::Mat NormalizeMask(const cv::Mat& mask, const char* what) {
  if (mask.empty()) throw InputError(fmt::format("{}: empty mask", what));
  if (mask.depth() != CV_8U) {
    throw InputError(fmt::format("{}: mask must be 8-bit (CV_8U), got depth {}", what, mask.depth()));
  }
  cv::Mat single;
  if (mask.channels() == 1) {
    single = mask;
  } else {
    std::vector<cv::Mat> planes;
    cv::split(mask, planes);
    single = planes[0].clone();
    for (size_t c = 1; c < planes.size(); ++c) cv::max(single, planes[c], single);
  }
  cv::Mat binary;
  cv::compare(single, 0, binary, cv::CMP_NE);  // 255 where non-zero
  return binary;
}

}  // namespace

struct PoissonSystem::Impl {
  PoissonOptions options;
  cv::Size size;
  cv::Mat mask;  // H x W CV_8U, 255 in Ω
  PoissonSolverKind solver = PoissonSolverKind::kDirect;
  double prepare_seconds = 0.0;
  std::vector<int32_t> unknown_pixels;  // y * W + x of each unknown, row-major
  cv::Mat index;                        // H x W CV_32S: compact index of an unknown, −1 for known pixels
  cv::Mat no_data;  // H x W CV_8U, non-zero = no value and no edge (like outside the image); empty = none
  cv::Mat cut_right, cut_down;  // H x W CV_8U, non-zero = that edge is left out; empty = none

  // Whether the edge from the unknown (y, x) to its neighbour (ny, nx) is part of the equation.
  bool Linked(int y, int x, int ny, int nx) const {
    if (ny < 0 || ny >= size.height || nx < 0 || nx >= size.width) return false;
    if (!no_data.empty() && no_data.at<uint8_t>(ny, nx) != 0) return false;
    if (!cut_right.empty() && ny == y && cut_right.at<uint8_t>(y, std::min(x, nx)) != 0) return false;
    if (!cut_down.empty() && nx == x && cut_down.at<uint8_t>(std::min(y, ny), x) != 0) return false;
    return true;
  }
  std::unique_ptr<DirectSolver> direct;
  std::unique_ptr<MaskedMultigrid> multigrid;

  // ||b − A x|| for compact vectors (double precision).
  double ResidualNorm(const Eigen::VectorXd& b, const Eigen::VectorXd& x) const {
    const int W = size.width;
    std::vector<double> partial(unknown_pixels.size());
    ParallelForRange(
        static_cast<int64_t>(unknown_pixels.size()),
        [&](int64_t begin, int64_t end) {
          for (int64_t k = begin; k < end; ++k) {
            const int y = unknown_pixels[k] / W, x_ = unknown_pixels[k] % W;
            double ax = 0.0;
            int degree = 0;
            auto visit = [&](int ny, int nx) {
              if (!Linked(y, x_, ny, nx)) return;
              ++degree;
              const int n = index.at<int32_t>(ny, nx);
              if (n >= 0) ax -= x[n];
            };
            visit(y, x_ - 1);
            visit(y, x_ + 1);
            visit(y - 1, x_);
            visit(y + 1, x_);
            ax += degree * x[k];
            partial[k] = (b[k] - ax) * (b[k] - ax);
          }
        },
        4096);
    double sum = 0.0;
    for (double value : partial) sum += value;
    return std::sqrt(sum);
  }
};

PoissonSystem::PoissonSystem() = default;
PoissonSystem::~PoissonSystem() = default;
PoissonSystem::PoissonSystem(const PoissonSystem&) = default;
PoissonSystem& PoissonSystem::operator=(const PoissonSystem&) = default;
PoissonSystem::PoissonSystem(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

const PoissonSystem::Impl& PoissonSystem::impl() const {
  if (!impl_) throw std::logic_error("PoissonSystem used before PreparePoisson");
  return *impl_;
}
cv::Size PoissonSystem::ImageSize() const { return impl().size; }
int PoissonSystem::NumUnknowns() const { return static_cast<int>(impl().unknown_pixels.size()); }
PoissonSolverKind PoissonSystem::Solver() const { return impl().solver; }
const cv::Mat& PoissonSystem::Mask() const { return impl().mask; }
double PoissonSystem::PrepareSeconds() const { return impl().prepare_seconds; }
const PoissonOptions& PoissonSystem::Options() const { return impl().options; }

PoissonSystem PreparePoisson(const cv::Mat& mask_in, const PoissonOptions& options) {
  return PreparePoisson(mask_in, options, PoissonLinks{});
}

PoissonSystem PreparePoisson(const cv::Mat& mask_in, const PoissonOptions& options,
                             const PoissonLinks& links) {
  const cv::Mat& no_data_in = links.no_data;
  options.Check();
  Timer timer;
  auto impl = std::make_shared<PoissonSystem::Impl>();
  impl->options = options;
  impl->mask = NormalizeMask(mask_in, "PreparePoisson");
  impl->size = impl->mask.size();
  const int W = impl->size.width, H = impl->size.height;
  bool no_data_touches_domain = false;
  if (!no_data_in.empty()) {
    if (no_data_in.size() != impl->size) {
      throw InputError(fmt::format("PreparePoisson: the no-data mask is {}x{}, the mask is {}x{}",
                                   no_data_in.cols, no_data_in.rows, W, H));
    }
    impl->no_data = NormalizeMask(no_data_in, "PreparePoisson (no-data mask)");
    impl->no_data.setTo(0, impl->mask);  // a pixel of Ω is an unknown, whatever the no-data mask says
    cv::Mat grown;
    cv::dilate(impl->no_data, grown, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)));
    no_data_touches_domain = cv::countNonZero(grown & impl->mask) > 0;
    if (!no_data_touches_domain) impl->no_data.release();  // nothing to leave out: the plain system
  }
  for (const auto& [cut, stored] :
       {std::pair{&links.cut_right, &impl->cut_right}, std::pair{&links.cut_down, &impl->cut_down}}) {
    if (cut->empty()) continue;
    if (cut->size() != impl->size || cut->type() != CV_8U) {
      throw InputError(fmt::format("PreparePoisson: an edge-cut mask must be {}x{} CV_8U", W, H));
    }
    if (cv::countNonZero(*cut) > 0) {
      *stored = *cut;
      no_data_touches_domain = true;  // (any cut: the multigrid hierarchy knows no cut edges either)
    }
  }
  const int num_unknowns = cv::countNonZero(impl->mask);
  if (num_unknowns == W * H) {
    throw InputError(fmt::format(
        "PreparePoisson: the mask ({}x{}) covers the whole image; at least one known pixel is needed for the "
        "Dirichlet boundary",
        W, H));
  }
  impl->index.create(impl->size, CV_32S);
  impl->unknown_pixels.reserve(num_unknowns);
  for (int y = 0; y < H; ++y) {
    const uint8_t* row = impl->mask.ptr<uint8_t>(y);
    int32_t* index_row = impl->index.ptr<int32_t>(y);
    for (int x = 0; x < W; ++x) {
      if (row[x]) {
        index_row[x] = static_cast<int32_t>(impl->unknown_pixels.size());
        impl->unknown_pixels.push_back(y * W + x);
      } else {
        index_row[x] = -1;
      }
    }
  }
  impl->solver = options.solver;
  if (impl->solver == PoissonSolverKind::kAuto) {
    impl->solver = num_unknowns <= options.auto_direct_max_unknowns ? PoissonSolverKind::kDirect
                                                                    : PoissonSolverKind::kMultigrid;
  }
  // The multigrid hierarchy knows only the image border as a no-flux boundary.
  if (no_data_touches_domain) impl->solver = PoissonSolverKind::kDirect;
  if (num_unknowns > 0) {
    if (impl->solver == PoissonSolverKind::kDirect) {
      std::vector<Eigen::Triplet<double>> triplets;
      triplets.reserve(static_cast<size_t>(num_unknowns) * 5);
      for (int k = 0; k < num_unknowns; ++k) {
        const int y = impl->unknown_pixels[k] / W, x = impl->unknown_pixels[k] % W;
        int degree = 0;
        auto visit = [&](int ny, int nx) {
          if (!impl->Linked(y, x, ny, nx)) return;
          ++degree;
          const int n = impl->index.at<int32_t>(ny, nx);
          if (n >= 0) triplets.emplace_back(k, n, -1.0);
        };
        visit(y, x - 1);
        visit(y, x + 1);
        visit(y - 1, x);
        visit(y + 1, x);
        triplets.emplace_back(k, k, static_cast<double>(degree));
      }
      Eigen::SparseMatrix<double> matrix(num_unknowns, num_unknowns);
      matrix.setFromTriplets(triplets.begin(), triplets.end());
      if (options.direct_backend == PoissonDirectBackend::kCholmod) {
        impl->direct = std::make_unique<CholmodSolver>(matrix);
      } else {
        impl->direct = std::make_unique<EigenLdltSolver>(matrix);
      }
    } else {
      impl->multigrid = std::make_unique<MaskedMultigrid>(impl->mask, options);
    }
  }
  impl->prepare_seconds = timer.Seconds();
  return PoissonSystem(std::move(impl));
}

std::string PoissonResult::Summary() const {
  return fmt::format("poisson {}: {} channel(s), {} iteration(s), relative residual {:.3g}, {:.3f} s",
                     ToString(solver), channels, iterations, relative_residual, seconds);
}

namespace {

template <typename T>
void SolveChannels(const PoissonSystem::Impl& system, const cv::Mat& boundary, const cv::Mat& divergence,
                   cv::Mat& output, PoissonResult& result) {
  const int W = system.size.width;
  const int n = boundary.channels();
  const auto num_unknowns = static_cast<int64_t>(system.unknown_pixels.size());
  for (int c = 0; c < n; ++c) {
    // b = −f + sum of Dirichlet neighbours.
    Eigen::VectorXd b(num_unknowns);
    ParallelForRange(
        num_unknowns,
        [&](int64_t begin, int64_t end) {
          for (int64_t k = begin; k < end; ++k) {
            const int y = system.unknown_pixels[k] / W, x = system.unknown_pixels[k] % W;
            double value = divergence.empty() ? 0.0 : -static_cast<double>(divergence.ptr<T>(y)[x * n + c]);
            auto visit = [&](int ny, int nx) {
              if (!system.Linked(y, x, ny, nx)) return;
              if (system.index.at<int32_t>(ny, nx) < 0) value += boundary.ptr<T>(ny)[nx * n + c];
            };
            visit(y, x - 1);
            visit(y, x + 1);
            visit(y - 1, x);
            visit(y + 1, x);
            b[k] = value;
          }
        },
        4096);
    Eigen::VectorXd x;
    if (system.direct) {
      x = system.direct->Solve(b);
    } else {
      std::vector<double> b_vector(b.data(), b.data() + b.size()), x_vector;
      const poisson_internal::MultigridStats stats = system.multigrid->Solve(b_vector, x_vector);
      if (!stats.converged) {
        throw std::runtime_error(fmt::format(
            "Poisson multigrid did not reach the relative residual {} within {} iterations (reached {:.3g})",
            system.options.tolerance, system.options.max_iterations, stats.relative_residual));
      }
      result.iterations = std::max(result.iterations, stats.iterations);
      x = Eigen::Map<Eigen::VectorXd>(x_vector.data(), static_cast<Eigen::Index>(x_vector.size()));
    }
    const double b_norm = b.norm();
    const double residual = b_norm > 0.0 ? system.ResidualNorm(b, x) / b_norm : system.ResidualNorm(b, x);
    result.relative_residual = std::max(result.relative_residual, residual);
    for (int64_t k = 0; k < num_unknowns; ++k) {
      const int y = system.unknown_pixels[k] / W, px = system.unknown_pixels[k] % W;
      output.ptr<T>(y)[px * n + c] = static_cast<T>(x[k]);
    }
  }
}

}  // namespace

// A NaN or inf among the values the solve reads (boundary pixels next to Ω, or the divergence in Ω) would
// spread through the whole hole; refuse it, naming the first such pixel. Values elsewhere are not read.
static void RefuseNonFinite(const cv::Mat& values, const cv::Mat& mask, bool inside, const char* what) {
  // Row by row over the mask alone (no image of the grid's size: a thin band in a 10-megapixel grid reads a
  // few hundred thousand values); the first pixel in row-major order is named, as cv::checkRange would.
  const int rows = mask.rows, cols = mask.cols, channels = values.channels();
  const bool is_double = values.depth() == CV_64F;
  const auto finite = [&](int r, int c) {
    for (int k = 0; k < channels; ++k) {
      const double v = is_double ? values.ptr<double>(r)[c * channels + k]
                                 : static_cast<double>(values.ptr<float>(r)[c * channels + k]);
      if (!std::isfinite(v)) return false;
    }
    return true;
  };
  for (int r = 0; r < rows; ++r) {
    const uint8_t* here = mask.ptr<uint8_t>(r);
    const uint8_t* above = r > 0 ? mask.ptr<uint8_t>(r - 1) : nullptr;
    const uint8_t* below = r + 1 < rows ? mask.ptr<uint8_t>(r + 1) : nullptr;
    for (int c = 0; c < cols; ++c) {
      bool read = here[c] != 0;
      if (!inside) {
        // Next to the hole: outside it, with a pixel of it among the 3 x 3 around.
        if (read) continue;
        for (int dc = -1; dc <= 1 && !read; ++dc) {
          const int x = c + dc;
          if (x < 0 || x >= cols) continue;
          read = here[x] || (above != nullptr && above[x]) || (below != nullptr && below[x]);
        }
      }
      if (read && !finite(r, c)) {
        throw InputError(
            fmt::format("SolvePoisson: {} holds NaN or inf at pixel (x {}, y {}) {} the hole; fix "
                        "or mask that pixel",
                        what, c, r, inside ? "inside" : "next to"));
      }
    }
  }
}

PoissonResult SolvePoisson(const PoissonSystem& system_handle, const cv::Mat& boundary_in,
                           const cv::Mat& divergence_in) {
  const PoissonSystem::Impl& system = system_handle.impl();
  Timer timer;
  if (boundary_in.empty()) throw InputError("SolvePoisson: empty boundary image");
  if (boundary_in.size() != system.size) {
    throw InputError(fmt::format("SolvePoisson: boundary image is {}x{}, the mask is {}x{}", boundary_in.cols,
                                 boundary_in.rows, system.size.width, system.size.height));
  }
  const int depth = boundary_in.depth() == CV_64F ? CV_64F : CV_32F;
  const int n = boundary_in.channels();
  cv::Mat boundary;
  boundary_in.convertTo(boundary, depth);  // copies: the input is never modified
  cv::Mat divergence;
  if (!divergence_in.empty()) {
    if (divergence_in.size() != system.size || divergence_in.channels() != n) {
      throw InputError(fmt::format(
          "SolvePoisson: divergence is {}x{} with {} channel(s), expected {}x{} with {} (the boundary's)",
          divergence_in.cols, divergence_in.rows, divergence_in.channels(), system.size.width,
          system.size.height, n));
    }
    // Only read: no copy when it is already of the solve's depth (a 10-megapixel grid's divergence is 120 MB).
    if (divergence_in.depth() == depth) {
      divergence = divergence_in;
    } else {
      divergence_in.convertTo(divergence, depth);
    }
  }
  RefuseNonFinite(boundary, system_handle.Mask(), /*inside=*/false, "the boundary image");
  if (!divergence.empty())
    RefuseNonFinite(divergence, system_handle.Mask(), /*inside=*/true, "the divergence");
  PoissonResult result;
  result.unknowns = static_cast<int>(system.unknown_pixels.size());
  result.solver = system.solver;
  result.channels = n;
  result.image = boundary;
  if (!system.unknown_pixels.empty()) {
    if (depth == CV_64F) {
      SolveChannels<double>(system, boundary, divergence, result.image, result);
    } else {
      SolveChannels<float>(system, boundary, divergence, result.image, result);
    }
  }
  result.seconds = timer.Seconds();
  return result;
}

PoissonResult FillLaplace(const PoissonSystem& system, const cv::Mat& image) {
  PoissonResult result = SolvePoisson(system, image, cv::Mat());
  result.operation = PoissonOperation::kFill;
  return result;
}

PoissonResult ReconstructFromGradients(const PoissonSystem& system, const cv::Mat& boundary,
                                       const cv::Mat& gx, const cv::Mat& gy) {
  PoissonResult result = SolvePoisson(system, boundary, BackwardDivergence(gx, gy));
  result.operation = PoissonOperation::kReconstruct;
  return result;
}

cv::Mat CloneMaskInTarget(const cv::Mat& source_mask, cv::Size target_size, cv::Point offset) {
  const cv::Mat mask = NormalizeMask(source_mask, "SeamlessClone");
  const cv::Rect box = cv::boundingRect(mask);
  const cv::Rect placed = box + offset;
  if (box.area() > 0 && (placed & cv::Rect(0, 0, target_size.width, target_size.height)) != placed) {
    throw InputError(fmt::format(
        "SeamlessClone: the cloned region (source box {}x{} at ({}, {})) placed at offset ({}, {}) lands at "
        "({}, {})–({}, {}), outside the {}x{} target",
        box.width, box.height, box.x, box.y, offset.x, offset.y, placed.x, placed.y, placed.br().x - 1,
        placed.br().y - 1, target_size.width, target_size.height));
  }
  cv::Mat target_mask = cv::Mat::zeros(target_size, CV_8U);
  if (box.area() > 0) mask(box).copyTo(target_mask(placed));
  return target_mask;
}

cv::Mat CloneDivergence(const cv::Mat& source_in, const cv::Mat& source_mask, cv::Size target_size,
                        cv::Point offset) {
  if (source_in.empty()) throw InputError("SeamlessClone: empty source image");
  if (source_mask.size() != source_in.size()) {
    throw InputError(fmt::format("SeamlessClone: mask is {}x{}, the source is {}x{}", source_mask.cols,
                                 source_mask.rows, source_in.cols, source_in.rows));
  }
  const cv::Mat target_mask = CloneMaskInTarget(source_mask, target_size, offset);
  const int depth = source_in.depth() == CV_64F ? CV_64F : CV_32F;
  cv::Mat source;
  source_in.convertTo(source, depth);
  // Divergence of the source's own gradients (edges leaving the source image are 0), placed at the offset;
  // the solver reads it only inside the pasted region, which lies inside the target.
  const cv::Mat source_divergence = Laplacian5(source);
  cv::Mat divergence = cv::Mat::zeros(target_size, CV_MAKETYPE(depth, source.channels()));
  const cv::Rect source_rect(0, 0, source.cols, source.rows);
  const cv::Rect placed = (source_rect + offset) & cv::Rect(0, 0, target_size.width, target_size.height);
  if (placed.area() > 0) source_divergence(placed - offset).copyTo(divergence(placed), target_mask(placed));
  return divergence;
}

PoissonResult SeamlessClone(const cv::Mat& source, const cv::Mat& source_mask, const cv::Mat& target,
                            cv::Point offset, const PoissonOptions& options) {
  options.Check();
  if (target.empty()) throw InputError("SeamlessClone: empty target image");
  if (source.empty()) throw InputError("SeamlessClone: empty source image");
  if (source.channels() != target.channels()) {
    throw InputError(fmt::format("SeamlessClone: source has {} channel(s), target {}", source.channels(),
                                 target.channels()));
  }
  if (source_mask.size() != source.size()) {
    throw InputError(fmt::format("SeamlessClone: mask is {}x{}, the source is {}x{}", source_mask.cols,
                                 source_mask.rows, source.cols, source.rows));
  }
  const int depth = (source.depth() == CV_64F || target.depth() == CV_64F) ? CV_64F : CV_32F;
  // Only the pasted region and its 1-pixel ring matter, so the work is done on that window of the target
  // (cost follows the region, not the images); the solution is the same as on the whole target, because the
  // window is cut by the target's border only where the target itself ends.
  const cv::Mat target_mask_check =
      CloneMaskInTarget(source_mask, target.size(), offset);  // validates placement
  const cv::Rect region = cv::boundingRect(target_mask_check);
  PoissonResult result;
  result.operation = PoissonOperation::kClone;
  cv::Mat output;
  target.convertTo(output, depth);
  if (region.area() == 0) {
    result.image = output;
    result.channels = output.channels();
    return result;
  }
  const cv::Rect window = cv::Rect(region.x - 1, region.y - 1, region.width + 2, region.height + 2) &
                          cv::Rect(cv::Point(), target.size());
  const cv::Rect window_in_source = (window - offset) & cv::Rect(cv::Point(), source.size());
  cv::Mat source_window;
  source(window_in_source).convertTo(source_window, depth);
  const cv::Mat window_mask = target_mask_check(window);
  cv::Mat divergence = cv::Mat::zeros(window.size(), CV_MAKETYPE(depth, source.channels()));
  const cv::Rect placed(window_in_source.tl() + offset - window.tl(), window_in_source.size());
  Laplacian5(source_window).copyTo(divergence(placed), window_mask(placed));
  const PoissonSystem system = PreparePoisson(window_mask, options);
  result = SolvePoisson(system, output(window), divergence);
  result.operation = PoissonOperation::kClone;
  result.image.copyTo(output(window));
  result.image = output;
  return result;
}

}  // namespace lidarshop
