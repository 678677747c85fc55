// The error of a relative-pose measurement between two poses (odometry, loop
// closures, a measured rig transform, a pose-graph edge), in 2D and 3D.
//
// Poses x = (p, R) map local to parent coordinates (x = world_from_frame):
// SE(2) ambient [x, y, θ], SE(3) ambient [p, qx, qy, qz, qw]; tangent [δp, δθ]
// (translation first; ⊞ is the compound Rᵈ × SO(d): p + δp, R·exp(δθ)). The
// measurement z = (t_z, R_z), ambient likewise, is the pose of frame j seen
// from frame i (i_from_j). With
//   x_ij = xᵢ⁻¹ xⱼ = (t_ij, R_ij) = (Rᵢᵀ (pⱼ − pᵢ), Rᵢᵀ Rⱼ)
//   Δ = z⁻¹ x_ij:    t_Δ = R_zᵀ (t_ij − t_z),   R_Δ = R_zᵀ R_ij
// the error e ∈ R³ (2D) or R⁶ (3D), always ordered [translation part,
// rotation part], is one of three conventions, each a tag type below:
//   pose_error::G2o       g2o's EdgeSE2 / EdgeSE3 (toVectorMQT):
//       2D e = [t_Δ, wrap(θ_Δ)] (also GTSAM's BetweenFactor<Pose2> with
//          Pose2's default chart);
//       3D e = [t_Δ, vec(q_Δ)], q_Δ the unit quaternion of R_Δ with w ≥ 0 and
//          vec its [x, y, z] part (≈ half the rotation angle; not doubled).
//   pose_error::Log       GTSAM's BetweenFactor with the Lie-group chart
//       ("SO(3)-log"): e = Log_SE(d)(Δ), reordered [u, ω] so that the file's
//       information matrix applies unchanged (GTSAM orders its tangent [ω, u]
//       and permutes Ω instead). ω = log(R_Δ), u = V(ω)⁻¹ t_Δ with V the left
//       Jacobian (differs from t_Δ by O(|ω|·|t|)):
//         2D  u = [[a, b], [−b, a]] t_Δ,  b = θ/2, a = b·cot(b)
//         3D  u = t − ½ ω×t + c(θ) ω×(ω×t),  c(θ) = (1 − (θ/2)cot(θ/2)) / θ²
//   pose_error::Compound  boxplus' own ⊟ of the compound Rᵈ × SO(d) manifold
//       (Hertzberg et al. 2013, Sec. 3.3): e = x_ij ⊟ z = [t_ij − t_z,
//       log(R_zᵀ R_ij)] — the translation difference is not rotated into z's
//       frame. What boxplus.Problem.add_relative_pose uses.
// The residual is r = W e with W the noise's whitening (order [x, y, θ] or
// [x, y, z, rx, ry, rz]; for NoiseModel::Information(Ω), WᵀW = Ω as g2o files
// store it), so Σ‖r‖² is the convention's chi2 (g2o's chi2; 2× GTSAM's
// graph.error()). Blocks: xᵢ (3 or 7), xⱼ (3 or 7).
//
// SE-Sync's chordal objective is not an error of Δ: it is its own residual
// kind (chordal_relative_pose.h); the run-time choice between all four is
// PoseErrorConvention (pose_error_convention.h), which the factories take.
//
// Derivatives: 2D g2o and 3D g2o/log have analytic Jacobians (tested against
// autodiff of the templates below and against central differences). SE(2)'s
// ⊞ has an identity Jacobian, so its ambient and tangent Jacobians coincide;
// for SE(3) the tangent Jacobian J_t (6×6) is returned in ambient form
// J_t·4Qᵀ for the rotation columns, Q = ∂(q⊗exp(δ))/∂δ (4×3, QᵀQ = I/4), so
// that Ceres' product with the manifold's PlusJacobian gives back exactly J_t.
// The other combinations use autodiff of the templates.
#pragma once

#include <memory>
#include <type_traits>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/pose/pose_error_convention.h"
#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/manifolds/se2.h"
#include "boxplus/manifolds/se3.h"
#include "boxplus/noise.h"

namespace boxplus {

// The error conventions as types: the templates below are instantiated for
// these only, so no run-time check sits inside an autodiff functor.
namespace pose_error {
struct G2o {
  static constexpr PoseErrorConvention kConvention = PoseErrorConvention::kG2o;
};
struct Log {
  static constexpr PoseErrorConvention kConvention = PoseErrorConvention::kLog;
};
struct Compound {
  static constexpr PoseErrorConvention kConvention = PoseErrorConvention::kCompound;
};
template <class C>
inline constexpr bool kIsConvention =
    std::is_same_v<C, G2o> || std::is_same_v<C, Log> || std::is_same_v<C, Compound>;
}  // namespace pose_error

// Calls f(tag) with the tag of an error convention and returns true; returns
// false for kSESync, which has no error of Δ (chordal_relative_pose.h).
template <class F>
bool WithErrorConvention(PoseErrorConvention c, F&& f) {
  switch (c) {
    case PoseErrorConvention::kG2o:
      f(pose_error::G2o{});
      return true;
    case PoseErrorConvention::kLog:
      f(pose_error::Log{});
      return true;
    case PoseErrorConvention::kCompound:
      f(pose_error::Compound{});
      return true;
    case PoseErrorConvention::kSESync:
      return false;
  }
  return false;
}

// x_ij = xᵢ⁻¹ xⱼ of two SE(3) poses (7 ambient entries), any scalar type.
template <typename T>
void RelativePose3DBetween(const T* xi, const T* xj, T* x_ij) {
  T qi_inv[4], dp[3];
  QuatConjugate(xi + 3, qi_inv);
  for (int k = 0; k < 3; ++k) dp[k] = xj[k] - xi[k];
  QuatRotatePoint(qi_inv, dp, x_ij);
  QuatMultiply(qi_inv, xj + 3, x_ij + 3);
}

// t_Δ and q_Δ of Δ = z⁻¹ (xᵢ⁻¹ xⱼ) for any scalar type.
template <typename T>
void RelativePose3DDelta(const T* xi, const T* xj, const double* z, T* t_delta, T* q_delta) {
  T x_ij[7], zq_inv[4], tz[3];
  RelativePose3DBetween(xi, xj, x_ij);
  const T zq[4] = {T(z[3]), T(z[4]), T(z[5]), T(z[6])};
  QuatConjugate(zq, zq_inv);
  for (int k = 0; k < 3; ++k) tz[k] = x_ij[k] - T(z[k]);
  QuatRotatePoint(zq_inv, tz, t_delta);
  QuatMultiply(zq_inv, x_ij + 3, q_delta);
}

// e (3) of SE(2) poses xi, xj and z = [x, y, θ] in convention C.
template <class C, typename T, std::enable_if_t<pose_error::kIsConvention<C>, int> = 0>
void RelativePose2DError(const T* xi, const T* xj, const double* z, T* e) {
  using std::cos;
  using std::sin;
  const T ci = cos(xi[2]), si = sin(xi[2]);
  const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
  const T tx = ci * dx + si * dy - z[0];  // R_iᵀ(p_j − p_i) − t_z
  const T ty = -si * dx + ci * dy - z[1];
  e[2] = WrapAngle(T(xj[2] - xi[2] - z[2]));
  if constexpr (std::is_same_v<C, pose_error::Compound>) {
    e[0] = tx;
    e[1] = ty;
    return;
  }
  const double cz = std::cos(z[2]), sz = std::sin(z[2]);
  e[0] = cz * tx + sz * ty;
  e[1] = -sz * tx + cz * ty;
  if constexpr (std::is_same_v<C, pose_error::Log>) {
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

// e (6) of SE(3) poses xi, xj and z = [t, qx, qy, qz, qw] (unit) in convention C.
template <class C, typename T, std::enable_if_t<pose_error::kIsConvention<C>, int> = 0>
void RelativePose3DError(const T* xi, const T* xj, const double* z, T* e) {
  if constexpr (std::is_same_v<C, pose_error::Compound>) {
    T x_ij[7], zt[7];
    RelativePose3DBetween(xi, xj, x_ij);
    for (int k = 0; k < 7; ++k) zt[k] = T(z[k]);
    SE3Ops::Minus(x_ij, zt, e);
    return;
  }
  T t[3], q[4];
  RelativePose3DDelta(xi, xj, z, t, q);
  if constexpr (std::is_same_v<C, pose_error::G2o>) {
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

// Cost functions r = W e. z = [x, y, θ] with a 3-dim noise, or [t, qx, qy,
// qz, qw] (normalised here) with a 6-dim noise (checked: boxplus::Error
// otherwise). kSESync returns the chordal residual (chordal_relative_pose.h;
// 6 or 12 residuals, whitened by ChordalNoise(noise)). Analytic Jacobians
// where the header says so, autodiff otherwise.
std::shared_ptr<ceres::CostFunction> MakeRelativePose2D(
    const Eigen::Vector3d& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);
std::shared_ptr<ceres::CostFunction> MakeRelativePose3D(
    const Eigen::Matrix<double, 7, 1>& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);
// Autodiff of the templates in any convention (for tests and comparisons).
std::shared_ptr<ceres::CostFunction> MakeRelativePose2DAutoDiff(
    const Eigen::Vector3d& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);
std::shared_ptr<ceres::CostFunction> MakeRelativePose3DAutoDiff(
    const Eigen::Matrix<double, 7, 1>& z, const NoiseModel& noise,
    PoseErrorConvention convention = PoseErrorConvention::kG2o);

}  // namespace boxplus
