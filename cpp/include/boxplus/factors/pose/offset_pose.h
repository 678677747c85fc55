// A relative pose between two sensor frames mounted on two poses (g2o's
// EDGE_SE2_OFFSET, EDGE_SE3_OFFSET), and its unary form, a pose prior
// (EDGE_PRIOR_SE2, EDGE_SE3_PRIOR), where the first frame is the world origin.
//
// Poses a, b: SE2 ambient [x, y, θ] / SE3 [p, qx, qy, qz, qw], tangent
// [δp, δθ] (⊞ the compound Rᵈ × SO(d)). Offsets o_a = a_from_sensor_a,
// o_b = b_from_sensor_b: the PARAMS_SE2OFFSET [x, y, θ] / PARAMS_SE3OFFSET
// [t, qxyzw] lines (identity when the edge has none). Measurement
// z = sensor_a_from_sensor_b in the same layout. As g2o's computeError:
//   Δ = (a · o_a)⁻¹ · (b · o_b)        (EdgeSE2Offset / EdgeSE3Offset:
//                                        cacheFrom→w2n() · cacheTo→n2w())
//   prior: Δ = b · o_b                  (EdgeSE3Prior: cache→n2w(); EdgeSE2Prior
//                                        has no offset: o_b = identity)
//   e = E(z⁻¹ · Δ),  SE2: E = [t, wrap(θ)] (SE2::toVector, angle in [−π, π));
//                    SE3: E = [t, vec(q)], q with w ≥ 0 (internal::toVectorMQT).
// These edges exist only in g2o's files, so their error is g2o's in every pose
// error convention. Residual r = W e (W the noise's whitening: WᵀW = Ω as in
// the file, 3×3 or 6×6, order [x, y, θ] / [x, y, z, qx, qy, qz]).
// Blocks: a (3 or 7), b (3 or 7); the prior only b. Autodiff.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

// ab = a · b for SE2 [x, y, θ] (D = 2) or SE3 [t, qxyzw] (D = 3); ab may not alias.
template <int D, typename T, typename U, typename V>
void ComposePose(const U* a, const V* b, T* ab) {
  using std::cos;
  using std::sin;
  if constexpr (D == 2) {
    const T c = T(cos(a[2])), s = T(sin(a[2]));
    ab[0] = T(a[0]) + c * T(b[0]) - s * T(b[1]);
    ab[1] = T(a[1]) + s * T(b[0]) + c * T(b[1]);
    ab[2] = T(a[2]) + T(b[2]);
  } else {
    T qa[4], qb[4], tb[3], rtb[3];
    for (int k = 0; k < 4; ++k) qa[k] = T(a[3 + k]), qb[k] = T(b[3 + k]);
    for (int k = 0; k < 3; ++k) tb[k] = T(b[k]);
    QuatRotatePoint(qa, tb, rtb);
    for (int k = 0; k < 3; ++k) ab[k] = T(a[k]) + rtb[k];
    QuatMultiply(qa, qb, ab + 3);
  }
}

// ai = a⁻¹; ai may not alias.
template <int D, typename T>
void InversePose(const T* a, T* ai) {
  using std::cos;
  using std::sin;
  if constexpr (D == 2) {
    const T c = cos(a[2]), s = sin(a[2]);
    ai[0] = -(c * a[0] + s * a[1]);
    ai[1] = s * a[0] - c * a[1];
    ai[2] = -a[2];
  } else {
    QuatConjugate(a + 3, ai + 3);
    T rt[3];
    QuatRotatePoint(ai + 3, a, rt);
    for (int k = 0; k < 3; ++k) ai[k] = -rt[k];
  }
}

// e (3 or 6) of the formula above; a == nullptr: the prior (a = the origin).
// offset_a, offset_b, z: ambient layout (double).
template <int D, typename T>
void OffsetPoseError(const T* a, const T* b, const double* offset_a, const double* offset_b,
                     const double* z, T* e) {
  constexpr int N = D == 2 ? 3 : 7;
  T sb[N], delta[N], zd[N];
  ComposePose<D, T>(b, offset_b, sb);
  if (a) {
    T sa[N], sa_inv[N];
    ComposePose<D, T>(a, offset_a, sa);
    InversePose<D>(sa, sa_inv);
    ComposePose<D, T>(sa_inv, sb, delta);
  } else {
    for (int k = 0; k < N; ++k) delta[k] = sb[k];
  }
  T z_inv[N], zt[N];
  for (int k = 0; k < N; ++k) zt[k] = T(z[k]);
  InversePose<D>(zt, z_inv);
  ComposePose<D, T>(z_inv, delta, zd);
  if constexpr (D == 2) {
    e[0] = zd[0];
    e[1] = zd[1];
    e[2] = WrapAngle(zd[2]);
  } else {
    const T s = zd[6] < T(0.0) ? T(-1.0) : T(1.0);
    for (int k = 0; k < 3; ++k) {
      e[k] = zd[k];
      e[3 + k] = s * zd[3 + k];
    }
  }
}

// Binary: blocks a, b. offset_a / offset_b: ambient layout (3 or 7 numbers).
std::shared_ptr<ceres::CostFunction> MakeOffsetPose2D(const Eigen::Vector3d& z,
                                                      const Eigen::Vector3d& offset_a,
                                                      const Eigen::Vector3d& offset_b,
                                                      const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakeOffsetPose3D(const Eigen::Matrix<double, 7, 1>& z,
                                                      const Eigen::Matrix<double, 7, 1>& offset_a,
                                                      const Eigen::Matrix<double, 7, 1>& offset_b,
                                                      const NoiseModel& noise);
// Unary (the prior): one block, the pose.
std::shared_ptr<ceres::CostFunction> MakeOffsetPosePrior2D(const Eigen::Vector3d& z,
                                                           const Eigen::Vector3d& offset,
                                                           const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakeOffsetPosePrior3D(
    const Eigen::Matrix<double, 7, 1>& z, const Eigen::Matrix<double, 7, 1>& offset,
    const NoiseModel& noise);

}  // namespace boxplus
