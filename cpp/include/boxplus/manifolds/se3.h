// SE(3) as the compound R³ × SO(3) of the ⊞-method (MTKM paper, Sec. III).
//
// Ambient layout: [px, py, pz, qx, qy, qz, qw] (position, then the unit
// quaternion [x, y, z, w]; the layout of g2o's VERTEX_SE3:QUAT).
// Tangent order [δp (3), δθ (3)] — translation first, then rotation:
//   (p, R) ⊞ (δp, δθ) = (p + δp, R·exp(δθ))
//   (p₁, R₁) ⊟ (p₀, R₀) = (p₁ − p₀, log(R₀⁻¹ R₁))
// δp is in the parent frame, δθ in the body frame. A covariance of an SE3 is
// read in this tangent space, in this order. The pose maps local points to
// the parent frame: fromlocal(v) = R v + p (so a camera pose named
// world_from_cam maps p_in_cam to p_in_world).
#pragma once

#include <Eigen/Core>

#include "boxplus/manifolds/so3.h"

namespace boxplus {

struct SE3Ops {
  static constexpr int kAmbient = 7;
  static constexpr int kTangent = 6;
  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    for (int i = 0; i < 3; ++i) out[i] = x[i] + delta[i];
    QuatBoxPlus(x + 3, delta + 3, out + 3);
  }
  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    for (int i = 0; i < 3; ++i) out[i] = y[i] - x[i];
    QuatBoxMinus(y + 3, x + 3, out + 3);
  }
  static void PlusJacobian(const double* x, double* J) {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> Jm(J);
    Jm.setZero();
    Jm.topLeftCorner<3, 3>().setIdentity();
    double Jq[12];
    SO3Ops::PlusJacobian(x + 3, Jq);
    Jm.bottomRightCorner<4, 3>() = Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>>(Jq);
  }
  static void MinusJacobian(const double* x, double* J) {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> Jm(J);
    Jm.setZero();
    Jm.topLeftCorner<3, 3>().setIdentity();
    double Jq[12];
    SO3Ops::MinusJacobian(x + 3, Jq);
    Jm.bottomRightCorner<3, 4>() = Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(Jq);
  }
};

using SE3Manifold = OpsManifold<SE3Ops>;

// A rigid transform (p, R) mapping local to parent coordinates.
// Composition a * b = (a.p + R_a b.p, R_a R_b): apply b, then a.
class SE3 : public ManifoldValue<SE3, SE3Ops> {
 public:
  SE3() { x_ << 0, 0, 0, 0, 0, 0, 1; }
  SE3(const SO3& rot, const Eigen::Vector3d& pos) {
    BOXPLUS_CHECK(pos.allFinite(), "SE3: position must be finite");
    x_ << pos, rot.quat();
  }
  static SE3 FromMatrix(const Eigen::Matrix4d& T) {
    BOXPLUS_CHECK((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() < 1e-9,
                  "SE3: last row of a homogeneous matrix must be [0 0 0 1]");
    return SE3(SO3::FromMatrix(T.topLeftCorner<3, 3>()), T.topRightCorner<3, 1>());
  }
  static SE3 FromAmbient(const double* a) {
    return SE3(SO3::FromAmbient(a + 3), Eigen::Vector3d(a[0], a[1], a[2]));
  }
  // identity ⊞ [p, w] = (p, exp(w)): the compound's chart at the identity.
  static SE3 Exp(const Eigen::Matrix<double, 6, 1>& tangent) { return SE3().boxplus(tangent); }
  // x ⊟ identity = [p, log R]; Exp(Log()) is the identity map.
  Tangent Log() const { return boxminus(SE3()); }

  Eigen::Vector3d pos() const { return x_.head<3>(); }
  SO3 rotation() const { return SO3::FromAmbient(x_.data() + 3); }
  // Homogeneous 4×4 matrix mapping local to parent coordinates.
  Eigen::Matrix4d transform() const {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = rotation().matrix();
    T.topRightCorner<3, 1>() = pos();
    return T;
  }
  Eigen::Vector3d fromlocal(const Eigen::Vector3d& v) const { return rotation() * v + pos(); }
  Eigen::Vector3d tolocal(const Eigen::Vector3d& v) const {
    return rotation().inverse() * (v - pos());
  }
  SE3 inverse() const {
    const SO3 rinv = rotation().inverse();
    return SE3(rinv, -(rinv * pos()));
  }
  SE3 operator*(const SE3& b) const { return SE3(rotation() * b.rotation(), fromlocal(b.pos())); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return fromlocal(p); }
};

}  // namespace boxplus
