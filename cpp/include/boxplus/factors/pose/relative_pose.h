// Relative pose between two SE(3) variables (odometry, a measured rig
// transform, a pose-graph edge).
//
// Residual (6):  r = W ((a2world⁻¹ ∘ b2world) ⊟ z_b2a)
//   ⊟ of the compound R³ × SO(3): [p₁ − p₀, log(R₀ᵀR₁)], tangent order
//   [translation, rotation] (units of the poses; rad). W = L⁻¹, LLᵀ = Σ (6×6,
//   same order).
// Parameter blocks: a2world (SE3 7), b2world (SE3 7); z_b2a = the pose of b in
// a's frame, [p, q(x,y,z,w)].
#pragma once

#include <memory>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/se3.h"
#include "boxplus/noise.h"

namespace boxplus {

class RelativePoseFunctor {
 public:
  RelativePoseFunctor(const Eigen::Matrix<double, 7, 1>& z_b2a,
                      const Eigen::Matrix<double, 6, 6>& W)
      : z_(z_b2a), W_(W) {}

  template <typename T>
  bool operator()(const T* a2world, const T* b2world, T* residual) const {
    T qinv[4], d[3], b2a[7];
    QuatConjugate(a2world + 3, qinv);
    for (int i = 0; i < 3; ++i) d[i] = b2world[i] - a2world[i];
    QuatRotatePoint(qinv, d, b2a);
    QuatMultiply(qinv, b2world + 3, b2a + 3);
    T z[7];
    for (int i = 0; i < 7; ++i) z[i] = T(z_[i]);
    SE3Ops::Minus(b2a, z, residual);
    WhitenInPlace<6>(W_, residual);
    return true;
  }

 private:
  Eigen::Matrix<double, 7, 1> z_;
  Eigen::Matrix<double, 6, 6> W_;
};

std::shared_ptr<ceres::CostFunction> MakeRelativePoseFactor(
    const Eigen::Matrix<double, 7, 1>& z_b2a, const NoiseModel& noise);

}  // namespace boxplus
