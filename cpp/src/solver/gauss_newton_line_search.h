// Gauss–Newton with a backtracking (Armijo) line search on ⊞-manifolds.
//
// Ceres 2.1's line-search minimiser only offers gradient methods (BFGS,
// L-BFGS, nonlinear CG), so Gauss–Newton with a line search is written here,
// as g2o and GTSAM structure their solvers: each iteration assembles the
// normal equations H δ = −g (NormalEquations), solves them by a sparse
// Cholesky (SparseCholesky), and halves α in x ⊞ αδ until the cost decreases
// by at least 10⁻⁴·α·|gᵀδ| (Armijo; Nocedal & Wright, eq. 3.4). Robust losses
// enter as iteratively reweighted least squares (weight ρ'(‖r‖²)); the
// gradient is exact, so δ is always a descent direction.
//
// Progress goes through boxplus/progress.h and SolverOptions::on_iteration,
// with IterationInfo::step_length = α and trust_region_radius = 0. Only
// accepted points are left in the blocks, also when an evaluation throws.
//
// Internal to boxplus::Problem (method kGaussNewtonLineSearch).
#pragma once

#include <vector>

#include "boxplus/solver_options.h"
#include "least_squares.h"

namespace boxplus::internal {

// SolveSummary::message when no step length decreases the cost along the
// Gauss–Newton direction (termination "convergence"): the signal on which
// kGaussNewtonFallback hands over to Levenberg–Marquardt.
inline constexpr char kNoDecreaseMessage[] =
    "the line search found no decrease along the Gauss-Newton direction";

SolveSummary SolveGaussNewtonLineSearch(const std::vector<LsqBlock>& blocks,
                                        const std::vector<LsqTerm>& terms,
                                        const SolverOptions& options,
                                        const PrepareEvaluation& prepare);

}  // namespace boxplus::internal
