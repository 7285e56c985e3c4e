// Descriptions of the Poisson options and enums (util/options.h).
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<PoissonSolverKind>() {
  static const EnumInfo info = MakeEnumInfo<PoissonSolverKind>(
      "Poisson solver",
      {{PoissonSolverKind::kAuto, "auto", "direct up to auto_direct_max_unknowns unknowns, multigrid above"},
       {PoissonSolverKind::kDirect, "direct", "sparse Cholesky"},
       {PoissonSolverKind::kMultigrid, "multigrid", "multigrid-preconditioned conjugate gradients"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PoissonDirectBackend>() {
  static const EnumInfo info = MakeEnumInfo<PoissonDirectBackend>(
      "direct Poisson backend",
      {{PoissonDirectBackend::kCholmod, "cholmod", "CHOLMOD supernodal LL^T (SuiteSparse), AMD ordering"},
       {PoissonDirectBackend::kEigenLdlt, "eigen-ldlt", "Eigen SimplicialLDLT (for comparison)"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<PoissonOperation>() {
  static const EnumInfo info = MakeEnumInfo<PoissonOperation>(
      "Poisson operation", {{PoissonOperation::kSolve, "solve", "a given divergence (SolvePoisson)"},
                            {PoissonOperation::kFill, "fill", "Laplace hole filling"},
                            {PoissonOperation::kClone, "clone", "seamless cloning"},
                            {PoissonOperation::kReconstruct, "reconstruct", "from a gradient field"}});
  return info;
}

template <>
const StructInfo& InfoOf<PoissonOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PoissonOptions> b("PoissonOptions", "Poisson / Laplace solves on masked domains");
    b.Field(&PoissonOptions::solver, "solver", "linear solver");
    b.Field(&PoissonOptions::direct_backend, "direct_backend", "sparse Cholesky implementation");
    b.Field(&PoissonOptions::auto_direct_max_unknowns, "auto_direct_max_unknowns",
            "auto: the direct solver up to this many unknowns")
        .Unit("unknowns")
        .Min(0);
    b.Field(&PoissonOptions::tolerance, "tolerance", "multigrid: relative residual at which CG stops")
        .AboveZero()
        .Below(1);
    b.Field(&PoissonOptions::max_iterations, "max_iterations", "multigrid: CG iterations per channel").Min(1);
    b.Field(&PoissonOptions::smoothing_sweeps, "smoothing_sweeps",
            "multigrid: red-black Gauss-Seidel sweeps before and after each coarse correction")
        .Min(1);
    b.Field(&PoissonOptions::coarsest_max_unknowns, "coarsest_max_unknowns",
            "multigrid: coarsening stops at or below this many unknowns")
        .Unit("unknowns")
        .Min(1);
    b.Field(&PoissonOptions::max_levels, "max_levels", "multigrid: levels including the finest").Min(1);
    return b.Build();
  }();
  return info;
}

// In the order `lidarshop poisson --json` has always written them.
template <>
const StructInfo& InfoOf<PoissonResult>() {
  static const StructInfo info = [] {
    StructBuilder<PoissonResult> b("PoissonResult", "a Poisson solve (the image is not JSON)");
    b.Field(&PoissonResult::operation, "operation", "the equation solved");
    b.Field(&PoissonResult::unknowns, "unknowns", "pixels of the domain solved for").Unit("px");
    b.Field(&PoissonResult::solver, "solver", "the solver that ran");
    b.Field(&PoissonResult::channels, "channels", "right-hand sides solved");
    b.Field(&PoissonResult::iterations, "iterations",
            "CG iterations, the maximum over channels (0 for the direct solver)");
    b.Field(&PoissonResult::relative_residual, "relative_residual",
            "||b - A x|| / ||b||, the maximum over channels");
    b.Field(&PoissonResult::seconds, "seconds", "wall-clock time of the solve").Unit("s");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
