// Poisson image editing on a masked domain (Pérez, Gangnet, Blake, "Poisson Image Editing", SIGGRAPH 2003).
//
// The domain Ω is the set of non-zero pixels of an H x W CV_8U mask (the "unknown" pixels, e.g. a
// hole). For every channel we solve the discrete Poisson equation with Dirichlet values, taken from an
// image, on the pixels around Ω:
//
//   for p in Ω:  sum_{n in N(p)} (I(n) − I(p)) = f(p),   I(n) = boundary(n) for n not in Ω,
//
// where N(p) are p's in-image 4-neighbours (Neumann / natural boundary on the image border, see operators.h)
// and f = BackwardDivergence(G) for a guidance field G:
//   * Laplace hole filling       f = 0                        (FillLaplace)
//   * seamless cloning           f = div ∇S of a source S     (SeamlessClone)
//   * gradient reconstruction    f = div G                    (ReconstructFromGradients)
// The matrix (minus the 5-point Laplacian restricted to Ω) is symmetric positive definite as long as at least
// one pixel of the image is outside Ω; PreparePoisson throws InputError otherwise.
//
// Build once, solve many (as libigl's min_quad_with_fixed_precompute / _solve): PreparePoisson analyses the
// mask and factors the matrix (sparse Cholesky, CHOLMOD or Eigen) or builds a multigrid hierarchy;
// SolvePoisson then solves any number of right-hand sides / channels on that mask.
//
// Solvers:
//   * direct     supernodal sparse Cholesky (CHOLMOD, SuiteSparse) or Eigen's SimplicialLDLT; exact to
//                rounding.
//   * multigrid  conjugate gradients preconditioned by one geometric multigrid V-cycle on the masked grid
//                (MGPCG, McAdams, Sifakis, Teran, "A parallel multigrid Poisson solver for fluids simulation
//                on large grids", SCA 2010): red-black Gauss–Seidel smoothing parallel over rows,
//                cell-centred bilinear prolongation and its transpose as restriction, a coarse cell is
//                unknown only if none of its 2 x 2 children is a known in-image pixel, and a direct solve on
//                the coarsest level. Time and memory grow with the bounding box of Ω (plus a 1-pixel ring),
//                not with the image.
//
// Usage:
//   PoissonSystem system = PreparePoisson(hole_mask);              // once per mask
//   PoissonResult filled = FillLaplace(system, image);             // image: H x W CV_32FC3
//   PoissonResult depth  = ReconstructFromGradients(system, depth_boundary, gx, gy);
#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

enum class PoissonSolverKind {
  kAuto,       // direct below PoissonOptions::auto_direct_max_unknowns unknowns, multigrid above
  kDirect,     // sparse Cholesky (see direct_backend)
  kMultigrid,  // multigrid-preconditioned conjugate gradients
};

enum class PoissonDirectBackend {
  kCholmod,    // CHOLMOD supernodal LL^T (SuiteSparse), AMD ordering
  kEigenLdlt,  // Eigen::SimplicialLDLT (for comparison; slower on large systems)
};

template <>
const EnumInfo& EnumInfoOf<PoissonSolverKind>();
template <>
const EnumInfo& EnumInfoOf<PoissonDirectBackend>();

struct PoissonOptions {
  PoissonSolverKind solver = PoissonSolverKind::kAuto;
  PoissonDirectBackend direct_backend = PoissonDirectBackend::kCholmod;
  int auto_direct_max_unknowns = 20000;  // unknowns; kAuto uses the direct solver up to this size
  // Multigrid (MGPCG) only:
  double tolerance = 1e-6;   // relative residual ||b − A x||_2 / ||b||_2 at which CG stops; (0, 1)
  int max_iterations = 200;  // CG iterations per channel; if reached without tolerance, SolvePoisson throws
  int smoothing_sweeps =
      2;  // red-black Gauss–Seidel sweeps before and after each coarse-grid correction; >= 1
  int coarsest_max_unknowns =
      4000;             // unknowns; coarsening stops at or below this, that level is solved directly
  int max_levels = 16;  // levels including the finest; >= 1

  // Throws OptionsError naming the field when a value is out of range.
  void Check() const;
};

template <>
const StructInfo& InfoOf<PoissonOptions>();

// A prepared Poisson system: the domain of one mask and its factorization or multigrid hierarchy. Cheap to
// copy (shared, immutable), safe to use from several threads at once.
struct PoissonLinks;

class PoissonSystem {
 public:
  PoissonSystem();
  ~PoissonSystem();
  PoissonSystem(const PoissonSystem&);
  PoissonSystem& operator=(const PoissonSystem&);

  cv::Size ImageSize() const;        // W x H of the images it solves for
  int NumUnknowns() const;           // pixels in Ω
  PoissonSolverKind Solver() const;  // kDirect or kMultigrid (never kAuto)
  const cv::Mat& Mask() const;       // H x W CV_8U, 255 in Ω, 0 elsewhere
  double PrepareSeconds() const;     // wall-clock time PreparePoisson took
  const PoissonOptions& Options() const;

  struct Impl;
  const Impl& impl() const;

 private:
  explicit PoissonSystem(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
  friend PoissonSystem PreparePoisson(const cv::Mat& mask, const PoissonOptions& options,
                                      const PoissonLinks& links);
};

// Analyses `mask` (H x W, CV_8U, non-zero = unknown; 1- or 3-channel accepted, any non-zero channel
// counts) and prepares the chosen solver. A mask without unknowns is allowed (solving then copies
// the boundary image). Throws InputError for an empty or wrong-typed mask, or a mask with no known
// pixel; OptionsError for bad options.
PoissonSystem PreparePoisson(const cv::Mat& mask, const PoissonOptions& options = {});

// Edges left out of the equation, as an edge leaving the image is (natural boundary, no flux):
//   no_data    H x W CV_8U, non-zero = a pixel with no value at all (e.g. a LiDAR cell without a return):
//              every edge between Ω and it is left out and its boundary value is never read; pixels of Ω are
//              unknowns whatever this mask says;
//   cut_right  H x W CV_8U, non-zero at (y, x) = the edge between (y, x) and (y, x+1) is left out (e.g. a
//              depth discontinuity: the two sides are solved apart);
//   cut_down   likewise for the edge between (y, x) and (y+1, x).
// Empty masks leave nothing out. The divergence given to SolvePoisson must leave those edges out too
// (guidance 0 on them). Every connected part of Ω must still reach a known pixel with data through linked
// edges, or the matrix is singular and the factorization throws. With any left-out edge at Ω the direct
// solver is used (the multigrid hierarchy knows only the image border).
struct PoissonLinks {
  cv::Mat no_data, cut_right, cut_down;
};
PoissonSystem PreparePoisson(const cv::Mat& mask, const PoissonOptions& options, const PoissonLinks& links);

// The equation a PoissonResult solved: the entry point that made it.
enum class PoissonOperation {
  kSolve,        // SolvePoisson: a given divergence
  kFill,         // FillLaplace
  kClone,        // SeamlessClone
  kReconstruct,  // ReconstructFromGradients
};

// Described (operation, unknowns, solver, channels, iterations, relative_residual, seconds: the order of
// `lidarshop poisson --json`); the image is not JSON.
struct PoissonResult {
  cv::Mat image;  // H x W x n: the boundary image with Ω replaced by the solution
  PoissonOperation operation = PoissonOperation::kSolve;  // the entry point that made it
  int unknowns = 0;                                       // pixels of Ω solved for (each channel)
  PoissonSolverKind solver = PoissonSolverKind::kDirect;  // the solver that ran
  int channels = 0;                                       // right-hand sides solved
  int iterations = 0;              // CG iterations, the maximum over channels (0 for the direct solver)
  double relative_residual = 0.0;  // ||b − A x|| / ||b|| in double precision, maximum over channels
  double seconds = 0.0;            // wall-clock time of the solve (not of PreparePoisson)

  std::string Summary() const;  // one line: solver, unknowns/channels, iterations, residual, seconds
};

template <>
const EnumInfo& EnumInfoOf<PoissonOperation>();
template <>
const StructInfo& InfoOf<PoissonResult>();

// Solves the system for every channel:
//   boundary    H x W x n (any depth; CV_64F stays double, everything else is solved in double and
//               returned as CV_32F): Dirichlet values are read from the pixels outside Ω; values inside Ω
//               are ignored;
//   divergence  H x W x n, f in the equation above, or an empty Mat for f = 0 (Laplace); read only inside Ω.
// Throws InputError when sizes or channel counts differ from the system's, and std::runtime_error when the
// multigrid solver does not reach the tolerance within max_iterations.
PoissonResult SolvePoisson(const PoissonSystem& system, const cv::Mat& boundary,
                           const cv::Mat& divergence = {});

// Laplace (membrane) hole filling: ∇²I = 0 in Ω, I = image outside Ω.
PoissonResult FillLaplace(const PoissonSystem& system, const cv::Mat& image);

// Reconstruction from a guidance gradient field (gx, gy as laid out by ForwardGradient): ∇²I = div G in Ω,
// I = boundary outside Ω. Reconstructing an image from its own ForwardGradient returns the image.
PoissonResult ReconstructFromGradients(const PoissonSystem& system, const cv::Mat& boundary,
                                       const cv::Mat& gx, const cv::Mat& gy);

// Seamless cloning (Pérez et al. 2003, "importing gradients"): the region `source_mask` (Hs x Ws, CV_8U,
// non-zero = clone) of `source` (Hs x Ws x n) is pasted into `target` (Ht x Wt x n) with source pixel (0, 0)
// at target pixel `offset` (x, y), solving ∇²I = div ∇S in the pasted region with I = target around it.
// Guidance edges that would leave the source image are 0. The pasted region must lie inside the target
// (InputError otherwise). Output: Ht x Wt x n, CV_32F (CV_64F for double inputs); values are not clamped.
PoissonResult SeamlessClone(const cv::Mat& source, const cv::Mat& source_mask, const cv::Mat& target,
                            cv::Point offset, const PoissonOptions& options = {});

// The two halves of SeamlessClone, for reuse of one prepared system:
//   CloneMaskInTarget  Ht x Wt CV_8U mask of the pasted region (255 inside);
//   CloneDivergence    Ht x Wt x n divergence of the source gradients placed at `offset` (0 outside the
//                      region).
cv::Mat CloneMaskInTarget(const cv::Mat& source_mask, cv::Size target_size, cv::Point offset);
cv::Mat CloneDivergence(const cv::Mat& source, const cv::Mat& source_mask, cv::Size target_size,
                        cv::Point offset);

}  // namespace lidarshop
