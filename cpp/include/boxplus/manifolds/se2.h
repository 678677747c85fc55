// SE(2) as the compound R² × SO(2) of the ⊞-method (MTKM paper, Sec. III).
//
// Ambient layout: [x, y, φ]. Tangent order [δx, δy, δφ] (translation, then
// rotation), component-wise:
//   (p, φ) ⊞ (δp, δφ) = (p + δp, wrap(φ + δφ))
//   (p₁, φ₁) ⊟ (p₀, φ₀) = (p₁ − p₀, wrap(φ₁ − φ₀))
// The translation is in the parent frame. A covariance of an SE2 is read in
// this tangent space. The pose maps local points to the parent frame:
// fromlocal(v) = R(φ) v + p.
#pragma once

#include <Eigen/Core>

#include "boxplus/manifolds/so2.h"

namespace boxplus {

struct SE2Ops {
  static constexpr int kAmbient = 3;
  static constexpr int kTangent = 3;
  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    out[0] = x[0] + delta[0];
    out[1] = x[1] + delta[1];
    out[2] = WrapAngle(T(x[2] + delta[2]));
  }
  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    out[0] = y[0] - x[0];
    out[1] = y[1] - x[1];
    out[2] = WrapAngle(T(y[2] - x[2]));
  }
  static void PlusJacobian(const double*, double* J) {
    Eigen::Map<Eigen::Matrix3d>(J).setIdentity();
  }
  static void MinusJacobian(const double*, double* J) {
    Eigen::Map<Eigen::Matrix3d>(J).setIdentity();
  }
};

using SE2Manifold = OpsManifold<SE2Ops>;

// A planar pose: position p and orientation φ, mapping local to parent.
// Composition a * b = (a.p + R_a b.p, a.φ + b.φ).
class SE2 : public ManifoldValue<SE2, SE2Ops> {
 public:
  SE2() { x_.setZero(); }
  SE2(const Eigen::Vector2d& pos, double phi) {
    BOXPLUS_CHECK(pos.allFinite() && std::isfinite(phi), "SE2: position and angle must be finite");
    x_ << pos, WrapAngle(phi);
  }
  SE2(const Eigen::Vector2d& pos, const SO2& rot) : SE2(pos, rot.angle()) {}
  static SE2 FromMatrix(const Eigen::Matrix3d& T) {
    BOXPLUS_CHECK(std::abs(T(2, 0)) + std::abs(T(2, 1)) + std::abs(T(2, 2) - 1.0) < 1e-9,
                  "SE2: last row of a homogeneous matrix must be [0 0 1]");
    return SE2(T.block<2, 1>(0, 2), SO2::FromMatrix(T.block<2, 2>(0, 0)).angle());
  }
  static SE2 FromAmbient(const double* a) { return SE2(Eigen::Vector2d(a[0], a[1]), a[2]); }
  // identity ⊞ [p, φ] and x ⊟ identity: the compound's chart at the identity.
  static SE2 Exp(const Eigen::Vector3d& tangent) { return SE2().boxplus(tangent); }
  Tangent Log() const { return boxminus(SE2()); }

  Eigen::Vector2d pos() const { return x_.head<2>(); }
  double angle() const { return x_[2]; }
  SO2 rotation() const { return SO2(x_[2]); }
  // Homogeneous 3×3 matrix mapping local to parent coordinates.
  Eigen::Matrix3d transform() const {
    Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
    T.block<2, 2>(0, 0) = rotation().matrix();
    T.block<2, 1>(0, 2) = pos();
    return T;
  }
  Eigen::Vector2d fromlocal(const Eigen::Vector2d& v) const { return rotation() * v + pos(); }
  Eigen::Vector2d tolocal(const Eigen::Vector2d& v) const {
    return rotation().inverse() * (v - pos());
  }
  SE2 inverse() const {
    const SO2 rinv = rotation().inverse();
    return SE2(-(rinv * pos()), rinv.angle());
  }
  SE2 operator*(const SE2& b) const { return SE2(fromlocal(b.pos()), x_[2] + b.x_[2]); }
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const { return fromlocal(p); }
};

}  // namespace boxplus
