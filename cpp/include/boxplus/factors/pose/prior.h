// Prior (direct observation) of a variable on any ⊞-manifold.
//
// Residual (tangent dim of S):  r = W (x ⊟ z),  W = L⁻¹ with LLᵀ = Σ.
// Parameter block: x (ambient size of S). Autodiff through the manifold's ⊟,
// so the Jacobian is exact. Averaging many priors on one variable gives its
// weighted Karcher mean (the smoke test of the solver).
#pragma once

#include <memory>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

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

}  // namespace boxplus
