// SE(3) relative pose in g2o's and the log convention with analytic Jacobians.
#include <ceres/sized_cost_function.h>

#include <cmath>

#include <Eigen/Geometry>

#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/manifolds/so3.h"
#include "relative_pose_analytic.h"

namespace boxplus::internal {

namespace {

using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Mat3 Skew(const Eigen::Vector3d& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Ambient Jacobian whose product with SE3's PlusJacobian is the tangent
// Jacobian Jt: the rotation columns are Jt_rot · 4Qᵀ (QᵀQ = I/4 for a unit
// quaternion).
using RowJ = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
void ToAmbient(const Mat6& Jt, const double* q, double* out) {
  double Qd[12];
  SO3Ops::PlusJacobian(q, Qd);
  const Eigen::Map<const Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> Q(Qd);
  Eigen::Map<RowJ> J(out);
  J.leftCols<3>() = Jt.leftCols<3>();
  J.rightCols<4>() = 4.0 * Jt.rightCols<3>() * Q.transpose();
}

// g2o convention with analytic Jacobians (see the header for the formulas).
class RelativePose3DG2oCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePose3DG2oCost(const Eigen::Matrix<double, 7, 1>& z, const Mat6& U) : U_(U) {
    tz_ = z.head<3>();
    qz_ = Eigen::Quaterniond(z[6], z[3], z[4], z[5]).normalized();
    RzT_ = qz_.conjugate().toRotationMatrix();
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const double* xi = x[0];
    const double* xj = x[1];
    const Eigen::Map<const Eigen::Vector3d> pi(xi), pj(xj);
    const Eigen::Map<const Eigen::Quaterniond> qi(xi + 3), qj(xj + 3);
    const Mat3 RiT = qi.conjugate().toRotationMatrix();
    const Eigen::Vector3d tij = RiT * (pj - pi);
    const Eigen::Quaterniond qij = qi.conjugate() * qj;
    Eigen::Quaterniond qd = qz_.conjugate() * qij;
    if (qd.w() < 0) qd.coeffs() = -qd.coeffs();
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = RzT_ * (tij - tz_);
    e.tail<3>() = qd.vec();
    Eigen::Map<Eigen::Matrix<double, 6, 1>> residuals_map(residuals);
    residuals_map = U_ * e;
    if (!jacobians) return true;

    // M = ∂vec(q_Δ ⊗ [φ/2, 1])/∂φ = ½ (w I + [v]×).
    const Mat3 M = 0.5 * (qd.w() * Mat3::Identity() + Skew(qd.vec()));
    const Mat3 A = RzT_ * RiT;  // ∂t_Δ/∂p_j
    if (jacobians[0]) {
      Mat6 Jt;
      Jt.topLeftCorner<3, 3>() = -A;
      Jt.topRightCorner<3, 3>() = RzT_ * Skew(tij);
      Jt.bottomLeftCorner<3, 3>().setZero();
      Jt.bottomRightCorner<3, 3>() = -M * qij.toRotationMatrix().transpose();
      ToAmbient(U_ * Jt, xi + 3, jacobians[0]);
    }
    if (jacobians[1]) {
      Mat6 Jt;
      Jt.topLeftCorner<3, 3>() = A;
      Jt.topRightCorner<3, 3>().setZero();
      Jt.bottomLeftCorner<3, 3>().setZero();
      Jt.bottomRightCorner<3, 3>() = M;
      ToAmbient(U_ * Jt, xj + 3, jacobians[1]);
    }
    return true;
  }

 private:
  Eigen::Vector3d tz_;
  Eigen::Quaterniond qz_;
  Mat3 RzT_;
  Mat6 U_;
};

// SE(3)-log convention with analytic Jacobians. With Δ = z⁻¹(x_i⁻¹x_j),
// ω = log(R_Δ), W = [ω]×, c(θ) as in RelativePose3DError<pose_error::Log>:
//   u = V(ω)⁻¹ t_Δ = t_Δ − ½ ω×t_Δ + c ω×(ω×t_Δ)
//   ∂u/∂t_Δ = V⁻¹ = I − ½W + cW²,   ∂ω/∂φ = J_r⁻¹(ω) = I + ½W + cW²
//                                    (φ: R_Δ → R_Δ exp(φ))
//   ∂u/∂ω  = ½[t_Δ]× + c((ωᵀt)I + ωtᵀ − 2tωᵀ) + (ω×(ω×t)) ∂c/∂ω
// and the tangent derivatives of (t_Δ, φ) are those of the g2o convention:
//   p_i: (−A, 0)   θ_i: (R_zᵀ[R_iᵀ(p_j−p_i)]×, −R_ijᵀ)   p_j: (A, 0)   θ_j: (0, I)
// with A = R_zᵀR_iᵀ, R_ij = R_iᵀR_j. The error is computed by the same template
// function as the autodiff version (identical values).
class RelativePose3DLogCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePose3DLogCost(const Eigen::Matrix<double, 7, 1>& z, const Mat6& U) : z_(z), U_(U) {
    qz_ = Eigen::Quaterniond(z[6], z[3], z[4], z[5]).normalized();
    RzT_ = qz_.conjugate().toRotationMatrix();
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const double* xi = x[0];
    const double* xj = x[1];
    Eigen::Vector3d t;
    Eigen::Quaterniond qd;
    RelativePose3DDelta(xi, xj, z_.data(), t.data(), qd.coeffs().data());
    Eigen::Vector3d w;
    QuatLog(qd.coeffs().data(), w.data());
    const double th2 = w.squaredNorm();
    double c, dc;  // c(θ) and (dc/dθ)/θ, so that ∂c/∂ω = dc·ωᵀ
    if (th2 < 1e-6) {
      // The same series as RelativePose3DError, and its exact derivative.
      c = 1.0 / 12.0 + th2 / 720.0;
      dc = 2.0 / 720.0;
    } else {
      const double th = std::sqrt(th2);
      const double h = 0.5 * th;
      const double f = h / std::tan(h);
      c = (1.0 - f) / th2;
      if (th2 < 1e-2) {
        // d/dθ of 1/12 + θ²/720 + θ⁴/30240 + θ⁶/1209600, over θ (no cancellation).
        dc = 2.0 / 720.0 + 4.0 * th2 / 30240.0 + 6.0 * th2 * th2 / 1209600.0;
      } else {
        const double sh = std::sin(h);
        const double fp = 0.5 / std::tan(h) - th / (4.0 * sh * sh);
        dc = (-fp / th2 - 2.0 * (1.0 - f) / (th2 * th)) / th;
      }
    }
    const Mat3 W = Skew(w);
    const Mat3 W2 = W * W;
    const Eigen::Vector3d wwt = W2 * t;
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = t - 0.5 * w.cross(t) + c * wwt;
    e.tail<3>() = w;
    Eigen::Map<Eigen::Matrix<double, 6, 1>> residuals_map(residuals);
    residuals_map = U_ * e;
    if (!jacobians) return true;

    const Mat3 I = Mat3::Identity();
    const Mat3 Vinv = I - 0.5 * W + c * W2;
    const Mat3 Jrinv = I + 0.5 * W + c * W2;
    const Mat3 dudw = 0.5 * Skew(t) +
                      c * (w.dot(t) * I + w * t.transpose() - 2.0 * t * w.transpose()) +
                      dc * wwt * w.transpose();
    // U · ∂e/∂(t_Δ, φ) = [U_l Vinv,  U_l dudw Jrinv + U_r Jrinv], U = [U_l U_r].
    const Eigen::Matrix<double, 6, 3> Ut = U_.leftCols<3>() * Vinv;
    const Eigen::Matrix<double, 6, 3> Uphi = (U_.leftCols<3>() * dudw + U_.rightCols<3>()) * Jrinv;
    const Eigen::Map<const Eigen::Vector3d> pi(xi), pj(xj);
    const Eigen::Map<const Eigen::Quaterniond> qi(xi + 3), qj(xj + 3);
    const Mat3 RiT = qi.conjugate().toRotationMatrix();
    const Mat3 A = RzT_ * RiT;
    if (jacobians[0]) {
      Mat6 Jt;
      Jt.leftCols<3>() = -Ut * A;
      const Mat3 RijT = (qi.conjugate() * qj).toRotationMatrix().transpose();
      Jt.rightCols<3>() = Ut * (RzT_ * Skew(RiT * (pj - pi))) - Uphi * RijT;
      ToAmbient(Jt, xi + 3, jacobians[0]);
    }
    if (jacobians[1]) {
      Mat6 Jt;
      Jt.leftCols<3>() = Ut * A;
      Jt.rightCols<3>() = Uphi;
      ToAmbient(Jt, xj + 3, jacobians[1]);
    }
    return true;
  }

 private:
  Eigen::Matrix<double, 7, 1> z_;
  Eigen::Quaterniond qz_;
  Mat3 RzT_;
  Mat6 U_;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeRelativePose3DG2oAnalytic(
    const Eigen::Matrix<double, 7, 1>& z, const Mat6& W) {
  return std::make_shared<RelativePose3DG2oCost>(z, W);
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose3DLogAnalytic(
    const Eigen::Matrix<double, 7, 1>& z, const Mat6& W) {
  return std::make_shared<RelativePose3DLogCost>(z, W);
}

}  // namespace boxplus::internal
