// A continuous-time trajectory: a uniform cubic B-spline on R³ × SO(3).
//
// world_from_imu(t) of camera–IMU calibration in motion (Furgale, Rehder &
// Siegwart, IROS 2013), in the split form: the position is an ordinary cubic
// B-spline of the control positions, the rotation the cumulative B-spline of
// Kim, Kim & Shin (SIGGRAPH 1995), with its body angular velocity after Sommer
// et al. (CVPR 2020, Sec. 4). Control points are boxplus SE3 values [p, q]
// (q = [x, y, z, w]) at uniformly spaced knots t_i = t₀ + i·Δt; the segment
// t ∈ [t_i, t_{i+1}) uses control points i … i+3 and u = (t − t_i)/Δt:
//
//   p(u) = Σ_{j=0}^{3} B_j(u) p_{i+j},
//     B = (1/6)[(1−u)³, 3u³ − 6u² + 4, −3u³ + 3u² + 3u + 1, u³]
//   R(u) = R_i · Π_{j=1}^{3} Exp(B̃_j(u) d_j),   d_j = Log(R_{i+j−1}ᵀ R_{i+j}),
//     B̃ = (1/6)[6, 5 + 3u − 3u² + u³, 1 + 3u + 3u² − 2u³, u³]  (cumulative)
//   velocity v = ṗ, acceleration a = p̈ (world frame; d/dt = (1/Δt) d/du),
//   body angular velocity ω = Rᵀ Ṙ (as a vector), by the recursion
//     ω₀ = 0,  ω_j = A_jᵀ ω_{j−1} + B̃'_j(u) d_j,  A_j = Exp(B̃_j d_j),  ω = ω₃ / Δt,
//   body angular acceleration α = ω̇ (the same in body and world terms: R α is the
//   world's), by differentiating that recursion (Ȧ_jᵀ x = (A_jᵀ x) × B̃'_j d_j):
//     ω̇₀ = 0,  ω̇_j = A_jᵀ ω̇_{j−1} + B̃''_j(u) d_j + (A_jᵀ ω_{j−1}) × (B̃'_j d_j),
//     α = ω̇₃ / Δt²  (what an IMU away from the body origin feels: α × r).
//
// u may lie slightly outside [0, 1) (a time offset that moved a sample across
// a knot): the same polynomials extrapolate smoothly, which is what a
// Gauss–Newton step needs; callers re-assign segments between solves.
// Every function is a template over the scalar (double or ceres::Jet), so the
// factors built on it get exact Jacobians by autodiff, including ∂/∂t for a
// time offset.
#pragma once

#include "boxplus/manifolds/rotation_math.h"

namespace boxplus::spline {

// Control points per segment (cubic).
inline constexpr int kOrder = 4;

// B_j(u), B'_j(u), B''_j(u) of the uniform cubic B-spline.
template <typename T>
void Basis(const T& u, T b[4], T db[4], T ddb[4]) {
  const T u2 = u * u;
  const T u3 = u2 * u;
  const T w = T(1.0) - u;
  b[0] = w * w * w / T(6.0);
  b[1] = (T(3.0) * u3 - T(6.0) * u2 + T(4.0)) / T(6.0);
  b[2] = (T(-3.0) * u3 + T(3.0) * u2 + T(3.0) * u + T(1.0)) / T(6.0);
  b[3] = u3 / T(6.0);
  db[0] = -w * w / T(2.0);
  db[1] = (T(3.0) * u2 - T(4.0) * u) / T(2.0);
  db[2] = (T(-3.0) * u2 + T(2.0) * u + T(1.0)) / T(2.0);
  db[3] = u2 / T(2.0);
  ddb[0] = w;
  ddb[1] = T(3.0) * u - T(2.0);
  ddb[2] = T(-3.0) * u + T(1.0);
  ddb[3] = u;
}

// The cumulative basis B̃_j(u) and its first and second derivatives (B̃_0 = 1).
template <typename T>
void CumulativeBasis(const T& u, T b[4], T db[4], T ddb[4]) {
  const T u2 = u * u;
  const T u3 = u2 * u;
  b[0] = T(1.0);
  b[1] = (T(5.0) + T(3.0) * u - T(3.0) * u2 + u3) / T(6.0);
  b[2] = (T(1.0) + T(3.0) * u + T(3.0) * u2 - T(2.0) * u3) / T(6.0);
  b[3] = u3 / T(6.0);
  db[0] = T(0.0);
  db[1] = (T(3.0) - T(6.0) * u + T(3.0) * u2) / T(6.0);
  db[2] = (T(3.0) + T(6.0) * u - T(6.0) * u2) / T(6.0);
  db[3] = u2 / T(2.0);
  ddb[0] = T(0.0);
  ddb[1] = u - T(1.0);
  ddb[2] = T(1.0) - T(2.0) * u;
  ddb[3] = u;
}

// The trajectory at u of the segment whose control points are knots[0..3]
// (each [p(3), q(4)]), Δt the knot spacing. Any output may be null.
//   p, q: world_from_imu (position, quaternion [x, y, z, w])
//   v, a: velocity and acceleration in the world frame
//   omega: angular velocity in the body (imu) frame
//   alpha: angular acceleration in the body frame
template <typename T>
void Evaluate(const T* const* knots, const T& u, double dt, T* p, T* q, T* v, T* a, T* omega,
              T* alpha = nullptr) {
  T b[4], db[4], ddb[4];
  if (p != nullptr || v != nullptr || a != nullptr) {
    Basis(u, b, db, ddb);
    for (int k = 0; k < 3; ++k) {
      T pk(0.0), vk(0.0), ak(0.0);
      for (int j = 0; j < kOrder; ++j) {
        pk += b[j] * knots[j][k];
        vk += db[j] * knots[j][k];
        ak += ddb[j] * knots[j][k];
      }
      if (p != nullptr) p[k] = pk;
      if (v != nullptr) v[k] = vk / T(dt);
      if (a != nullptr) a[k] = ak / T(dt * dt);
    }
  }
  if (q == nullptr && omega == nullptr && alpha == nullptr) return;
  T cb[4], cdb[4], cddb[4];
  CumulativeBasis(u, cb, cdb, cddb);
  T rot[4] = {knots[0][3], knots[0][4], knots[0][5], knots[0][6]};
  T w[3] = {T(0.0), T(0.0), T(0.0)};
  T dw[3] = {T(0.0), T(0.0), T(0.0)};
  for (int j = 1; j < kOrder; ++j) {
    T inv_prev[4], rel[4], d[3], scaled[3], A[4], A_inv[4], next[4], w_rot[3];
    QuatConjugate(knots[j - 1] + 3, inv_prev);
    QuatMultiply(inv_prev, knots[j] + 3, rel);
    QuatLog(rel, d);
    for (int k = 0; k < 3; ++k) scaled[k] = cb[j] * d[k];
    QuatExp(scaled, A);
    QuatMultiply(rot, A, next);
    for (int k = 0; k < 4; ++k) rot[k] = next[k];
    QuatConjugate(A, A_inv);
    QuatRotatePoint(A_inv, w, w_rot);
    if (alpha != nullptr) {
      T dw_rot[3], rate[3], cross[3];
      QuatRotatePoint(A_inv, dw, dw_rot);
      for (int k = 0; k < 3; ++k) rate[k] = cdb[j] * d[k];
      cross[0] = w_rot[1] * rate[2] - w_rot[2] * rate[1];
      cross[1] = w_rot[2] * rate[0] - w_rot[0] * rate[2];
      cross[2] = w_rot[0] * rate[1] - w_rot[1] * rate[0];
      for (int k = 0; k < 3; ++k) dw[k] = dw_rot[k] + cddb[j] * d[k] + cross[k];
    }
    for (int k = 0; k < 3; ++k) w[k] = w_rot[k] + cdb[j] * d[k];
  }
  if (q != nullptr) {
    for (int k = 0; k < 4; ++k) q[k] = rot[k];
  }
  if (omega != nullptr) {
    for (int k = 0; k < 3; ++k) omega[k] = w[k] / T(dt);
  }
  if (alpha != nullptr) {
    for (int k = 0; k < 3; ++k) alpha[k] = dw[k] / T(dt * dt);
  }
}

}  // namespace boxplus::spline
