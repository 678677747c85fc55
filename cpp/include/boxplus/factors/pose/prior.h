// Prior (direct observation) of a variable on any ⊞-manifold.
//
// Residual (tangent dim of S):  r = W (x ⊟ z),  W = L⁻¹ with LLᵀ = Σ.
// Parameter block: x (ambient size of S). Autodiff through the manifold's ⊟,
// so the Jacobian is exact. Averaging many priors on one variable gives its
// weighted Karcher mean (the smoke test of the solver).
//
// PriorFunctor<Ops> fixes S at compile time; MakePrior chooses it at run time
// from the variable's manifold.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>

#include "boxplus/noise.h"

namespace boxplus {

template <class Ops>
class PriorFunctor {
 public:
  using Ambient = Eigen::Matrix<double, Ops::kAmbient, 1>;
  using Weight = Eigen::Matrix<double, Ops::kTangent, Ops::kTangent>;
  PriorFunctor(const Ambient& z, const Weight& sqrt_info) : z_(z), sqrt_info_(sqrt_info) {}

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    T zt[Ops::kAmbient];
    for (int i = 0; i < Ops::kAmbient; ++i) zt[i] = T(z_[i]);
    Eigen::Matrix<T, Ops::kTangent, 1> e;
    Ops::Minus(x, zt, e.data());
    Eigen::Map<Eigen::Matrix<T, Ops::kTangent, 1>> r(residual);
    r = sqrt_info_.template cast<T>() * e;
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Ambient& z, const Weight& sqrt_info) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<PriorFunctor, Ops::kTangent, Ops::kAmbient>>(
        new PriorFunctor(z, sqrt_info));
  }

 private:
  Ambient z_;
  Weight sqrt_info_;
};

// A prior on a variable of any built-in manifold (Rⁿ, SO2, SO3, SE2, SE3,
// S2), looked up by the manifold's type in one table (each is a final class:
// manifolds.h). W = noise.sqrt_information() (tangent dim × tangent dim).
// Throws boxplus::Error naming `what` for other manifolds or sizes that do
// not match.
std::shared_ptr<ceres::CostFunction> MakePrior(const ceres::Manifold& manifold,
                                               const Eigen::VectorXd& z_ambient,
                                               const NoiseModel& noise, const std::string& what);

// A prior on some coordinates of an Rⁿ variable: r = W (x[i₁..iₘ] − z), W =
// noise.sqrt_information() (m × m). The other coordinates are left to the data
// (their Jacobian columns are zero), so the prior adds no information there, as
// a prior with zero weight on them would but cannot (W must be invertible).
// Throws boxplus::Error naming `what` for other manifolds, indices out of range
// or repeated, and sizes that do not match.
std::shared_ptr<ceres::CostFunction> MakeCoordinatePrior(const ceres::Manifold& manifold,
                                                         const std::vector<int>& indices,
                                                         const Eigen::VectorXd& z,
                                                         const NoiseModel& noise,
                                                         const std::string& what);

}  // namespace boxplus
