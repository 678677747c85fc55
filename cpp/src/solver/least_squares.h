// The least-squares problem as boxplus' own solvers see it: parameter blocks
// on manifolds and residual terms over them, minimising ½ Σ ρ(‖r‖²).
//
// Internal to boxplus::Problem, which builds these views of its variables and
// measurements for one solve.
#pragma once

#include <functional>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

namespace boxplus::internal {

struct LsqBlock {
  double* x;  // ambient values, updated in place (only accepted points are left)
  const ceres::Manifold* manifold;
  bool fixed;
  // x ⊞ δ = x + δ: the Plus Jacobian is the identity and is never formed
  // (an Rⁿ block of size n would otherwise cost n² doubles).
  bool euclidean = false;
};

struct LsqTerm {
  const ceres::CostFunction* cost;
  const ceres::LossFunction* loss;  // may be null
  std::vector<int> blocks;          // indices into the block list
};

// Called before every evaluation at a new point (Problem's evaluation hooks).
using PrepareEvaluation = std::function<void(bool evaluate_jacobians)>;

}  // namespace boxplus::internal
