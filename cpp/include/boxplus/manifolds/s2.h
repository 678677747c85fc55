// S²: unit vectors in R³ (directions, plane normals, gravity), 2 DOF.
//
// Ambient layout: [x, y, z] with unit norm. Tangent: δ ∈ R², coordinates in an
// orthonormal basis {b₁(x), b₂(x)} of the plane orthogonal to x.
//   x ⊞ δ = cos|δ| x + sinc|δ| (δ₁ b₁ + δ₂ b₂)
//   y ⊟ x = atan2(|v|, xᵀy) v / |v|,   v = [b₁ᵀy, b₂ᵀy]
// i.e. x ⊞ δ = R_x exp(δ) with R_x = [x b₁ b₂] orthogonal (Hertzberg et al.,
// Sec. 3.6). R_x is a Householder reflection, chosen by the sign of x's first
// coordinate so that it is never near its singular point. (x⊞δ)⊟x = δ for
// |δ| < π; y = −x is the cut locus, where ⊟ returns a vector of length π.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/manifolds/ops_manifold.h"
#include "boxplus/manifolds/rotation_math.h"

namespace boxplus {

struct S2Ops {
  static constexpr int kAmbient = 3;
  static constexpr int kTangent = 2;

  // b1, b2: columns 2 and 3 of R_x.
  template <typename T>
  static void Basis(const T* x, T* b1, T* b2) {
    const bool positive = !(x[0] < T(0.0));
    // R_x = −H(e₁ + x) if x₀ ≥ 0, else H(e₁ − x); H(u) = I − 2uuᵀ/|u|².
    const T s = positive ? T(1.0) : T(-1.0);
    const T u[3] = {T(1.0) + s * x[0], s * x[1], s * x[2]};
    const T k = T(2.0) / (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    // column j of H: e_j − k u u_j; R_x column j = −s·(that) for s = +1,
    // and +(that) for s = −1, i.e. −s (e_j − k u u_j).
    for (int i = 0; i < 3; ++i) {
      b1[i] = -s * ((i == 1 ? T(1.0) : T(0.0)) - k * u[i] * u[1]);
      b2[i] = -s * ((i == 2 ? T(1.0) : T(0.0)) - k * u[i] * u[2]);
    }
  }

  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    T b1[3], b2[3];
    Basis(x, b1, b2);
    const T theta_sq = delta[0] * delta[0] + delta[1] * delta[1];
    T c, sinc;
    if (theta_sq < T(kSmallAngleSq)) {
      c = T(1.0) - theta_sq / T(2.0);
      sinc = T(1.0) - theta_sq / T(6.0);
    } else {
      const T theta = sqrt(theta_sq);
      c = cos(theta);
      sinc = sin(theta) / theta;
    }
    for (int i = 0; i < 3; ++i) {
      out[i] = c * x[i] + sinc * (delta[0] * b1[i] + delta[1] * b2[i]);
    }
    const T n = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (int i = 0; i < 3; ++i) out[i] /= n;
  }

  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    using std::atan2;
    using std::sqrt;
    T b1[3], b2[3];
    Basis(x, b1, b2);
    const T w = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    const T v0 = b1[0] * y[0] + b1[1] * y[1] + b1[2] * y[2];
    const T v1 = b2[0] * y[0] + b2[1] * y[1] + b2[2] * y[2];
    const T s_sq = v0 * v0 + v1 * v1;
    T k;
    if (s_sq < T(kSmallAngleSq) && w > T(0.0)) {
      // atan2(s, w) / s = (1 / w)(1 − s² / (3 w²)) + O(s⁴)
      k = (T(1.0) - s_sq / (T(3.0) * w * w)) / w;
    } else if (s_sq == T(0.0)) {
      out[0] = T(kPi);  // y = −x: every direction is a shortest path.
      out[1] = T(0.0);
      return;
    } else {
      const T s = sqrt(s_sq);
      k = atan2(s, w) / s;
    }
    out[0] = k * v0;
    out[1] = k * v1;
  }

  static void PlusJacobian(const double* x, double* J) {
    double b1[3], b2[3];
    Basis(x, b1, b2);
    for (int i = 0; i < 3; ++i) {
      J[2 * i] = b1[i];
      J[2 * i + 1] = b2[i];
    }
  }
  static void MinusJacobian(const double* x, double* J) {
    double b1[3], b2[3];
    Basis(x, b1, b2);
    for (int i = 0; i < 3; ++i) {
      J[i] = b1[i];
      J[3 + i] = b2[i];
    }
  }
};

using S2Manifold = OpsManifold<S2Ops>;

// A unit 3-vector.
class S2 : public ManifoldValue<S2, S2Ops> {
 public:
  S2() { x_ << 1, 0, 0; }
  // Normalises v; throws on a zero or non-finite vector.
  explicit S2(const Eigen::Vector3d& v) {
    // Scaled by its largest entry first, so huge finite entries normalise too.
    const double scale = v.allFinite() ? v.cwiseAbs().maxCoeff() : NAN;
    BOXPLUS_CHECK(std::isfinite(scale) && scale > 0 && (scale >= 1 || v.norm() > 1e-12),
                  "S2: vector must be finite and non-zero, got [", v.transpose(), "]");
    const Eigen::Vector3d u = v / scale;
    x_ = u / u.norm();
  }
  static S2 FromAmbient(const double* a) { return S2(Eigen::Vector3d(a[0], a[1], a[2])); }
  Eigen::Vector3d vec() const { return x_; }
  // Orthonormal basis of the tangent plane used by ⊞/⊟ (3 × 2).
  Eigen::Matrix<double, 3, 2> tangent_basis() const {
    Eigen::Matrix<double, 3, 2> B;
    double b1[3], b2[3];
    S2Ops::Basis(x_.data(), b1, b2);
    B.col(0) = Eigen::Vector3d(b1[0], b1[1], b1[2]);
    B.col(1) = Eigen::Vector3d(b2[0], b2[1], b2[2]);
    return B;
  }
};

}  // namespace boxplus
