// Measurements evaluated in bulk outside Ceres' per-residual loop.
//
// Some measurements are cheapest to evaluate all at once: a vectorised Python
// function over a whole batch, or code that shares work between residuals.
// Such a group implements ResidualCache: before Ceres evaluates the problem,
// Problem's evaluation hook calls Prepare(), which computes every *error*
// e = f(Y) ⊟ z of the group, and, when asked, each error's Jacobian in the
// *tangent* spaces of its variables. One CachedCostFunction per measurement
// then serves Ceres from that cache, whitening with the measurement's
// NoiseModel as every C++ factor does (r = W e, ∂r = W ∂e): the noise of a
// Python measurement lives in C++ like any other, and Problem::Error
// un-whitens it on the same path.
//
// Ceres wants Jacobians with respect to ambient coordinates and multiplies
// them by PlusJacobian(x) itself. Any left inverse M of PlusJacobian
// (M·P = I, which Ceres requires of MinusJacobian) lifts a tangent Jacobian:
// (J_tan·M)·P = J_tan. That is what Evaluate does.
#pragma once

#include <memory>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>

#include "boxplus/noise.h"

namespace boxplus {

class ResidualCache {
 public:
  virtual ~ResidualCache() = default;
  // Computes residuals (and tangent Jacobians if `jacobians`) at the current
  // variable values. Returns false if the evaluation failed; the implementer
  // keeps the reason to report after the solve.
  virtual bool Prepare(bool jacobians, bool new_point) = 0;
  // Error of measurement `index` (residual_size doubles, not whitened).
  virtual const double* Error(int index) const = 0;
  // Row-major residual_size × tangent_size(slot) Jacobian of that error
  // with respect to the `slot`-th variable of measurement `index`.
  virtual const double* TangentJacobian(int index, int slot) const = 0;
  // false after a failed Prepare: Evaluate then reports failure to Ceres.
  virtual bool ok() const = 0;
};

class CachedCostFunction final : public ceres::CostFunction {
 public:
  // `manifolds` are those of the measurement's variables, in slot order; they
  // must outlive this object (Problem keeps them alive). `noise` has
  // dimension residual_size.
  CachedCostFunction(std::shared_ptr<ResidualCache> cache, int index, int residual_size,
                     std::vector<const ceres::Manifold*> manifolds, const NoiseModel& noise);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<ResidualCache> cache_;
  int index_;
  std::vector<const ceres::Manifold*> manifolds_;
  Eigen::MatrixXd W_;
};

}  // namespace boxplus
