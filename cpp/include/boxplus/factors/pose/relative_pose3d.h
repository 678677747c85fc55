// Relative-pose factor between two SE(3) poses, in two error conventions.
//
// Poses x = (p, R) map local to parent coordinates; ambient [p, qx, qy, qz,
// qw], tangent [δp, δθ] (translation first; ⊞ is the compound R³ × SO(3):
// p + δp, R·exp(δθ)). The measurement z = (t_z, R_z), ambient likewise, is the
// pose of frame j seen from frame i. With
//   Δ = z⁻¹ · (x_i⁻¹ · x_j),   t_Δ = R_zᵀ (R_iᵀ (p_j − p_i) − t_z),
//                              R_Δ = R_zᵀ R_iᵀ R_j,
// the error e ∈ R⁶, always ordered [translation part, rotation part], is
//   kG2o    (g2o's EdgeSE3, toVectorMQT):  e = [t_Δ, vec(q_Δ)], q_Δ the unit
//           quaternion of R_Δ with w ≥ 0 and vec its [x, y, z] part
//           (≈ half the rotation angle; not doubled);
//   kLog    (GTSAM's BetweenFactor<Pose3>, "SO(3)-log" convention):
//           e = [u, ω] with (ω, u) = Pose3::Logmap(Δ): ω = log(R_Δ) and
//           u = V(ω)⁻¹ t_Δ, V the left Jacobian of SO(3). GTSAM orders its
//           tangent [ω, u] and permutes the file's information matrix; here e
//           is reordered instead, so the file's Ω applies unchanged.
// Residual r = W e with W the noise's whitening (6×6, order [x, y, z, rx, ry,
// rz]; for NoiseModel::Information(Ω) WᵀW = Ω, Ω as stored in g2o files); Σ‖r‖² is the chi2 of the
// convention (g2o's chi2, or 2× GTSAM's graph.error()). Blocks: x_i (7), x_j (7). kG2o has analytic
// Jacobians: the tangent Jacobian J_t (6×6) is returned in ambient form J_t·4Qᵀ for the rotation
// columns, Q = ∂(q⊗exp(δ))/∂δ (4×3, QᵀQ = I/4), so that Ceres' product with
// the manifold's PlusJacobian gives back exactly J_t. kLog uses autodiff.
// kSESync is not an error of Δ: the factories return MakeRelativePose3DSESync
// (12 residuals, relative_pose_sesync.h); RelativePose3DError rejects
// it.
#pragma once

#include <memory>
#include <string>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/pose_error_convention.h"
#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

// t_Δ and q_Δ of Δ = z⁻¹ (x_i⁻¹ x_j) for any scalar type.
template <typename T>
void RelativePose3DDelta(const T* xi, const T* xj, const double* z, T* t_delta, T* q_delta) {
  T qi_inv[4], dp[3], tij[3], qij[4], zq_inv[4], tz[3];
  QuatConjugate(xi + 3, qi_inv);
  for (int k = 0; k < 3; ++k) dp[k] = xj[k] - xi[k];
  QuatRotatePoint(qi_inv, dp, tij);
  QuatMultiply(qi_inv, xj + 3, qij);
  const T zq[4] = {T(z[3]), T(z[4]), T(z[5]), T(z[6])};
  QuatConjugate(zq, zq_inv);
  for (int k = 0; k < 3; ++k) tz[k] = tij[k] - T(z[k]);
  QuatRotatePoint(zq_inv, tz, t_delta);
  QuatMultiply(zq_inv, qij, q_delta);
}

template <typename T>
void RelativePose3DError(const T* xi, const T* xj, const double* z, PoseErrorConvention convention,
                         T* e) {
  // SE-Sync's objective is not an error of Δ (relative_pose_sesync.h).
  BOXPLUS_CHECK(convention != PoseErrorConvention::kSESync,
                "RelativePose3DError: the sesync convention has its own residual "
                "(relative_pose_sesync.h)");
  T t[3], q[4];
  RelativePose3DDelta(xi, xj, z, t, q);
  if (convention == PoseErrorConvention::kG2o) {
    const T s = q[3] < T(0.0) ? T(-1.0) : T(1.0);
    for (int k = 0; k < 3; ++k) {
      e[k] = t[k];
      e[3 + k] = s * q[k];
    }
    return;
  }
  // Pose3::Logmap: u = t − ½ ω×t + c(θ) ω×(ω×t),
  // c(θ) = (1 − (θ/2)·cot(θ/2)) / θ² → 1/12 + θ²/720 for small θ.
  using std::sqrt;
  using std::tan;
  T w[3];
  QuatLog(q, w);
  const T th2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  T c;
  if (th2 < T(1e-6)) {
    c = T(1.0 / 12.0) + th2 / T(720.0);
  } else {
    const T th = sqrt(th2);
    c = (T(1.0) - th / (T(2.0) * tan(th / T(2.0)))) / th2;
  }
  const T wt[3] = {w[1] * t[2] - w[2] * t[1], w[2] * t[0] - w[0] * t[2], w[0] * t[1] - w[1] * t[0]};
  const T wwt[3] = {w[1] * wt[2] - w[2] * wt[1], w[2] * wt[0] - w[0] * wt[2],
                    w[0] * wt[1] - w[1] * wt[0]};
  for (int k = 0; k < 3; ++k) {
    e[k] = t[k] - T(0.5) * wt[k] + c * wwt[k];
    e[3 + k] = w[k];
  }
}

// z = [t, qx, qy, qz, qw] (normalised here), a 6-dim noise (checked).
// kG2o: analytic Jacobians; kLog: autodiff.
std::shared_ptr<ceres::CostFunction> MakeRelativePose3D(
    const Eigen::Matrix<double, 7, 1>& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);
// Autodiff in either convention (for tests and comparisons).
std::shared_ptr<ceres::CostFunction> MakeRelativePose3DAutoDiff(
    const Eigen::Matrix<double, 7, 1>& z, const NoiseModel& noise, PoseErrorConvention convention);

}  // namespace boxplus
