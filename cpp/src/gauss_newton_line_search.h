// Gauss–Newton with a backtracking (Armijo) line search on ⊞-manifolds.
//
// Ceres 2.1's line-search minimiser only offers gradient methods (BFGS,
// L-BFGS, nonlinear CG), so Gauss–Newton with a line search is written here,
// as g2o and GTSAM structure their solvers: the normal equations JᵀJ δ = −Jᵀr
// are assembled block by block into a sparse matrix whose pattern (in an AMD
// order of the variable graph) is fixed once, factorised by a sparse Cholesky
// (symbolic analysis once, numeric factorisation each iteration: Eigen's
// simplicial LDLᵀ, or CHOLMOD's supernodal LLᵀ when the factor fills in), and
// the step x ⊞ αδ is halved until the cost decreases by at least 10⁻⁴·α·|gᵀδ|. Robust losses enter as
// iteratively reweighted least squares (weight ρ'(‖r‖²)); the gradient is
// exact, so the direction is always a descent direction.
//
// Internal to boxplus::Problem (method kGaussNewtonLineSearch).
#pragma once

#include <functional>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include "boxplus/problem.h"

namespace boxplus::internal {

struct LsqBlock {
  double* x;  // ambient values, updated in place (only accepted points are left)
  const ceres::Manifold* manifold;
  bool fixed;
};

struct LsqTerm {
  const ceres::CostFunction* cost;
  const ceres::LossFunction* loss;  // may be null
  std::vector<int> blocks;          // indices into the block list
};

// Called before every evaluation at a new point (Problem's evaluation hooks).
using PrepareEvaluation = std::function<void(bool evaluate_jacobians)>;

SolveSummary SolveGaussNewtonLineSearch(const std::vector<LsqBlock>& blocks,
                                        const std::vector<LsqTerm>& terms,
                                        const SolverOptions& options,
                                        const PrepareEvaluation& prepare);

}  // namespace boxplus::internal
