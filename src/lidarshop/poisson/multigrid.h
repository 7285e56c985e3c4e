// Internal to the poisson module: the masked geometric multigrid behind PoissonSolverKind::kMultigrid.
//
// Conjugate gradients preconditioned by one symmetric V-cycle (MGPCG; McAdams, Sifakis, Teran, SCA 2010) for
// A x = b, A = −(5-point Laplacian) restricted to the unknown pixels of a mask, Dirichlet 0 at known pixels
// and Neumann at the image border (the operator of poisson.h). Vectors are "compact": one value per unknown
// pixel, in row-major order of the mask.
//
// The hierarchy lives on dense grids covering the mask's bounding box plus a 1-pixel ring (so cost follows
// the hole, not the image). Each level holds a cell type (outside the image / known / unknown); a coarse cell
// is known if any of its 2 x 2 children is known, else unknown if any child is unknown (so every coarse
// system keeps a Dirichlet boundary and stays positive definite). Operators are re-discretised 5-point
// stencils; prolongation is cell-centred bilinear (weights 9/16, 3/16, 3/16, 1/16, clamped at the grid edge)
// and restriction its exact transpose, smoothing is red-black Gauss–Seidel (red→black before, black→red after
// the coarse correction), and the coarsest level is solved by a sparse LDL^T factorization — so the V-cycle
// is a symmetric positive definite preconditioner. Every loop runs over rows in parallel; reductions sum
// per-row partials in row order, so results do not depend on the thread count.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/poisson/poisson.h"

namespace lidarshop::poisson_internal {

struct MultigridStats {
  int iterations = 0;
  double relative_residual = 0.0;  // of the CG recurrence; the caller recomputes the true residual
  bool converged = false;
};

class MaskedMultigrid {
 public:
  // mask: H x W CV_8U, non-zero = unknown, at least one unknown and one known pixel.
  MaskedMultigrid(const cv::Mat& mask, const PoissonOptions& options);
  ~MaskedMultigrid();

  int NumLevels() const;
  // Solves A x = b (compact vectors of NumUnknowns() values). Thread-safe (work arrays are per call).
  MultigridStats Solve(const std::vector<double>& b, std::vector<double>& x) const;

  struct Level;

 private:
  std::vector<std::unique_ptr<Level>> levels_;
  std::vector<int64_t> compact_to_grid_;  // level-0 memory index of each unknown
  PoissonOptions options_;
  struct Coarsest;
  std::unique_ptr<Coarsest> coarsest_;
};

}  // namespace lidarshop::poisson_internal
