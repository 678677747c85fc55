// SO(2): planar rotations stored as an angle.
//
// Ambient layout: [φ] with φ ∈ [−π, π) after ⊞. Tangent: δφ ∈ R.
//   x ⊞ δ = wrap(φ + δ)        y ⊟ x = wrap(φ_y − φ_x)
// where wrap maps to [−π, π). The difference is wrapped, not each angle (that
// is what keeps (x ⊞ δ) ⊟ x = δ for |δ| < π across the ±π seam).
#pragma once

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/manifolds/ops_manifold.h"
#include "boxplus/manifolds/rotation_math.h"

namespace boxplus {

struct SO2Ops {
  static constexpr int kAmbient = 1;
  static constexpr int kTangent = 1;
  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    out[0] = WrapAngle(T(x[0] + delta[0]));
  }
  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    out[0] = WrapAngle(T(y[0] - x[0]));
  }
  static void PlusJacobian(const double*, double* J) { J[0] = 1.0; }
  static void MinusJacobian(const double*, double* J) { J[0] = 1.0; }
};

using SO2Manifold = OpsManifold<SO2Ops>;

// A planar rotation by angle φ (radians).
class SO2 : public ManifoldValue<SO2, SO2Ops> {
 public:
  explicit SO2(double phi = 0.0) {
    BOXPLUS_CHECK(std::isfinite(phi), "SO2: angle must be finite");
    x_[0] = WrapAngle(phi);
  }
  static SO2 FromMatrix(const Eigen::Matrix2d& R) {
    BOXPLUS_CHECK(R.allFinite(), "SO2: matrix has non-finite entries");
    const double err = (R.transpose() * R - Eigen::Matrix2d::Identity()).norm();
    BOXPLUS_CHECK(err < 1e-6 && R.determinant() > 0,
                  "SO2: not a rotation matrix (|RᵀR − I| = ", err, ")");
    return SO2(std::atan2(R(1, 0), R(0, 0)));
  }
  static SO2 FromAmbient(const double* a) { return SO2(a[0]); }

  double angle() const { return x_[0]; }
  Eigen::Matrix2d matrix() const {
    const double c = std::cos(x_[0]), s = std::sin(x_[0]);
    Eigen::Matrix2d R;
    R << c, -s, s, c;
    return R;
  }
  SO2 inverse() const { return SO2(-x_[0]); }
  SO2 operator*(const SO2& b) const { return SO2(x_[0] + b.x_[0]); }
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const { return matrix() * p; }
};

}  // namespace boxplus
