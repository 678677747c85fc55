// Scalar-generic rotation formulas shared by SO(3), SE(3) and S².
//
// Every function is a template over the scalar type T so that the same code
// serves double and ceres::Jet (autodiff). Quaternions are stored
// [x, y, z, w], the order of Eigen's coeffs() and of g2o files (Ceres' own
// QuaternionManifold uses [w, x, y, z]; boxplus never does).
//
// Small-angle branches test the squared norm, never the norm: sqrt has an
// infinite derivative at zero, which would poison the Jet's dual part.
#pragma once

#include <cmath>

namespace boxplus {

inline constexpr double kPi = 3.14159265358979323846;

// Squared norms below this use a Taylor series; the truncation error is then
// O(1e-24), far below double precision, and the derivative stays exact.
inline constexpr double kSmallAngleSq = 1e-12;

// Wraps an angle to [-π, π). floor() has zero derivative for Jets, so the
// derivative of the result with respect to `a` is exactly 1.
template <typename T>
T WrapAngle(const T& a) {
  using std::floor;
  return a - T(2.0 * kPi) * floor((a + T(kPi)) / T(2.0 * kPi));
}

// out = a ⊗ b (Hamilton product), all in [x, y, z, w]. out may not alias.
template <typename T>
void QuatMultiply(const T* a, const T* b, T* out) {
  out[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
  out[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
  out[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
  out[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

// out = conj(q) = q⁻¹ for unit q.
template <typename T>
void QuatConjugate(const T* q, T* out) {
  out[0] = -q[0];
  out[1] = -q[1];
  out[2] = -q[2];
  out[3] = q[3];
}

// out = exp(δ) as a unit quaternion: rotation by |δ| about δ/|δ|.
template <typename T>
void QuatExp(const T* delta, T* out) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta_sq = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
  T w, k;  // out = [k δ, w]
  if (theta_sq < T(kSmallAngleSq)) {
    w = T(1.0) - theta_sq / T(8.0);
    k = T(0.5) - theta_sq / T(48.0);
  } else {
    const T theta = sqrt(theta_sq);
    w = cos(theta / T(2.0));
    k = sin(theta / T(2.0)) / theta;
  }
  out[0] = k * delta[0];
  out[1] = k * delta[1];
  out[2] = k * delta[2];
  out[3] = w;
}

// out = log(q) ∈ R³ with |out| ≤ π: q and −q give the same result, so the
// rotation, not its quaternion sign, determines the tangent vector.
template <typename T>
void QuatLog(const T* q, T* out) {
  using std::atan2;
  using std::sqrt;
  // Work on the representative with w ≥ 0 so that the angle is in [0, π]. At
  // exactly π (w = 0) both ±π·axis are valid; the first non-zero vector
  // component decides, so that the result depends on the rotation only.
  bool flip = q[3] < T(0.0);
  if (q[3] == T(0.0)) {
    flip = q[0] != T(0.0) ? q[0] < T(0.0) : q[1] != T(0.0) ? q[1] < T(0.0) : q[2] < T(0.0);
  }
  const T sign = flip ? T(-1.0) : T(1.0);
  const T x = sign * q[0], y = sign * q[1], z = sign * q[2], w = sign * q[3];
  const T s_sq = x * x + y * y + z * z;
  T k;  // out = k [x, y, z]
  if (s_sq < T(kSmallAngleSq)) {
    // 2 atan2(s, w) / s = (2 / w) (1 − s² / (3 w²)) + O(s⁴); w ≈ 1 here.
    k = T(2.0) / w * (T(1.0) - s_sq / (T(3.0) * w * w));
  } else {
    const T s = sqrt(s_sq);
    k = T(2.0) * atan2(s, w) / s;
  }
  out[0] = k * x;
  out[1] = k * y;
  out[2] = k * z;
}

// out = R(q) p, for unit q. out may not alias p.
template <typename T>
void QuatRotatePoint(const T* q, const T* p, T* out) {
  // t = 2 (v × p);  out = p + w t + v × t   (v the vector part of q)
  const T t0 = T(2.0) * (q[1] * p[2] - q[2] * p[1]);
  const T t1 = T(2.0) * (q[2] * p[0] - q[0] * p[2]);
  const T t2 = T(2.0) * (q[0] * p[1] - q[1] * p[0]);
  out[0] = p[0] + q[3] * t0 + (q[1] * t2 - q[2] * t1);
  out[1] = p[1] + q[3] * t1 + (q[2] * t0 - q[0] * t2);
  out[2] = p[2] + q[3] * t2 + (q[0] * t1 - q[1] * t0);
}

// Rescales q to unit norm; ⊞ calls this so that rounding errors do not
// accumulate over many solver steps.
template <typename T>
void QuatNormalize(T* q) {
  using std::sqrt;
  const T n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 4; ++i) q[i] /= n;
}

// x ⊞ δ = x ⊗ exp(δ) for SO(3) in quaternion form. out may alias neither.
template <typename T>
void QuatBoxPlus(const T* x, const T* delta, T* out) {
  T e[4];
  QuatExp(delta, e);
  QuatMultiply(x, e, out);
  QuatNormalize(out);
}

// y ⊟ x = log(x⁻¹ ⊗ y) for SO(3) in quaternion form.
template <typename T>
void QuatBoxMinus(const T* y, const T* x, T* out) {
  T xinv[4], d[4];
  QuatConjugate(x, xinv);
  QuatMultiply(xinv, y, d);
  QuatLog(d, out);
}

}  // namespace boxplus
