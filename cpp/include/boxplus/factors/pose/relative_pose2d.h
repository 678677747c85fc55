// Relative-pose factor between two SE(2) poses (odometry, loop closures).
//
// Poses x = (p, θ) map local to parent coordinates, ambient [x, y, θ], tangent
// [δx, δy, δθ] (translation first). The measurement z = (t_z, θ_z) is the pose
// of frame j seen from frame i. Error (g2o's EdgeSE2, which is also GTSAM's
// BetweenFactor<Pose2> with Pose2's default chart):
//   Δ = z⁻¹ · (x_i⁻¹ · x_j)
//   e = [t_Δ, θ_Δ] = [R_zᵀ (R_iᵀ (p_j − p_i) − t_z),  wrap(θ_j − θ_i − θ_z)]
// Residual r = W e with W the noise's whitening (3×3, order [x, y, θ]; for
// NoiseModel::Information(Ω) WᵀW = Ω, Ω as g2o files store it); ½‖r‖² = ½ eᵀΩe, so Σ‖r‖² is g2o's
// chi2. Blocks: x_i (3), x_j (3). kG2o: analytic Jacobians (tested against autodiff and central
// differences; SE2's ⊞ has an identity Jacobian, so ambient and tangent Jacobians coincide); kLog:
// autodiff. kSESync is not an error of Δ: the factories return MakeRelativePose2DSESync (6
// residuals, relative_pose_sesync.h), and RelativePose2DError rejects it.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/pose_error_convention.h"
#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

// The error e above for any scalar type (double or ceres::Jet).
template <typename T>
void RelativePose2DError(const T* xi, const T* xj, const double* z, T* e,
                         PoseErrorConvention convention = PoseErrorConvention::kG2o) {
  // SE-Sync's objective is not an error of Δ (relative_pose_sesync.h).
  BOXPLUS_CHECK(convention != PoseErrorConvention::kSESync,
                "RelativePose2DError: the sesync convention has its own residual "
                "(relative_pose_sesync.h)");
  using std::cos;
  using std::sin;
  const T ci = cos(xi[2]), si = sin(xi[2]);
  const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
  const T tx = ci * dx + si * dy - z[0];  // R_iᵀ(p_j − p_i) − t_z
  const T ty = -si * dx + ci * dy - z[1];
  const double cz = std::cos(z[2]), sz = std::sin(z[2]);
  e[0] = cz * tx + sz * ty;
  e[1] = -sz * tx + cz * ty;
  e[2] = WrapAngle(T(xj[2] - xi[2] - z[2]));
  if (convention == PoseErrorConvention::kLog) {
    using std::tan;
    const T th2 = e[2] * e[2];
    const T b = e[2] / T(2.0);
    // a = (θ/2) cot(θ/2) = 1 − θ²/12 − θ⁴/720 − ...
    const T a = th2 < T(1e-6) ? T(1.0) - th2 / T(12.0) - th2 * th2 / T(720.0) : b / tan(b);
    const T ux = a * e[0] + b * e[1];
    const T uy = -b * e[0] + a * e[1];
    e[0] = ux;
    e[1] = uy;
  }
}

// Cost function for z = [x, y, θ] and a 3-dim noise (checked: throws
// boxplus::Error otherwise). kG2o: analytic Jacobians; kLog: autodiff.
std::shared_ptr<ceres::CostFunction> MakeRelativePose2D(
    const Eigen::Vector3d& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);
// Autodiff in either convention (for tests and comparisons).
std::shared_ptr<ceres::CostFunction> MakeRelativePose2DAutoDiff(
    const Eigen::Vector3d& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);

}  // namespace boxplus
