// SO(3): 3D rotations.
//
// Ambient layout: unit quaternion [x, y, z, w] (4 doubles, Eigen's coeffs()
// order; NOT Ceres' [w, x, y, z]). Tangent: δθ ∈ R³, a rotation vector in the
// local (body) frame:
//   x ⊞ δ = x ⊗ exp(δ)          y ⊟ x = log(x⁻¹ ⊗ y),   |y ⊟ x| ≤ π
// (MTKM paper, Sec. III-A). q and −q are the same rotation: ⊟ gives the same
// result for either, ⊞ keeps the sign of x. Valid for all x, y; (x⊞δ)⊟x = δ
// holds for |δ| < π.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/manifolds/ops_manifold.h"
#include "boxplus/manifolds/rotation_math.h"

namespace boxplus {

struct SO3Ops {
  static constexpr int kAmbient = 4;
  static constexpr int kTangent = 3;
  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    QuatBoxPlus(x, delta, out);
  }
  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    QuatBoxMinus(y, x, out);
  }
  // d(x ⊗ exp(δ))/dδ at 0 = ½ [x]_L restricted to pure quaternions.
  static void PlusJacobian(const double* q, double* J) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double rows[12] = {w,  -z, y,   //
                             z,  w,  -x,  //
                             -y, x,  w,   //
                             -x, -y, -z};
    for (int i = 0; i < 12; ++i) J[i] = 0.5 * rows[i];
  }
  // d log(x⁻¹ ⊗ y)/dy at y = x = 2 · (vector part of [x⁻¹]_L).
  static void MinusJacobian(const double* q, double* J) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double rows[12] = {w,  z,  -y, -x,  //
                             -z, w,  x,  -y,  //
                             y,  -x, w,  -z};
    for (int i = 0; i < 12; ++i) J[i] = 2.0 * rows[i];
  }
};

using SO3Manifold = OpsManifold<SO3Ops>;

// A rotation. Composition a * b applies b first, then a (matrix order).
class SO3 : public ManifoldValue<SO3, SO3Ops> {
 public:
  SO3() { x_ << 0, 0, 0, 1; }

  // From a quaternion [x, y, z, w]; normalised. Throws on zero or non-finite.
  static SO3 FromQuaternion(const Eigen::Vector4d& xyzw) {
    // Scaled by its largest entry first: huge finite entries (1e308, whose norm
    // overflows) normalise too, as the g2o reader's do.
    const double scale = xyzw.allFinite() ? xyzw.cwiseAbs().maxCoeff() : NAN;
    BOXPLUS_CHECK(std::isfinite(scale) && scale > 0 && (scale >= 1 || xyzw.norm() > 1e-12),
                  "SO3: quaternion must be finite and non-zero, got [", xyzw.transpose(),
                  "] (order x y z w)");
    const Eigen::Vector4d u = xyzw / scale;
    SO3 r;
    r.x_ = u / u.norm();
    return r;
  }
  // From a rotation matrix; throws unless R is orthonormal with det +1
  // (within 1e-6), then projects to the nearest rotation.
  static SO3 FromMatrix(const Eigen::Matrix3d& R) {
    BOXPLUS_CHECK(R.allFinite(), "SO3: rotation matrix has non-finite entries");
    const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
    BOXPLUS_CHECK(err < 1e-6 && R.determinant() > 0,
                  "SO3: not a rotation matrix (|RᵀR − I| = ", err, ", det = ", R.determinant(),
                  ")");
    Eigen::Quaterniond q(R);
    return FromQuaternion(q.coeffs());
  }
  static SO3 Exp(const Eigen::Vector3d& w) {
    SO3 r;
    QuatExp(w.data(), r.x_.data());
    return r;
  }
  static SO3 FromAmbient(const double* a) {
    return FromQuaternion(Eigen::Vector4d(a[0], a[1], a[2], a[3]));
  }

  Eigen::Vector3d Log() const {
    Eigen::Vector3d w;
    QuatLog(x_.data(), w.data());
    return w;
  }
  Eigen::Vector4d quat() const { return x_; }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(x_[3], x_[0], x_[1], x_[2]); }
  Eigen::Matrix3d matrix() const { return quaternion().toRotationMatrix(); }
  SO3 inverse() const {
    SO3 r;
    QuatConjugate(x_.data(), r.x_.data());
    return r;
  }
  SO3 operator*(const SO3& b) const {
    SO3 r;
    QuatMultiply(x_.data(), b.x_.data(), r.x_.data());
    QuatNormalize(r.x_.data());
    return r;
  }
  // Rotates a point: R p.
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    Eigen::Vector3d out;
    QuatRotatePoint(x_.data(), p.data(), out.data());
    return out;
  }
};

}  // namespace boxplus
