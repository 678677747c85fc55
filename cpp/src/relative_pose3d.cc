#include "boxplus/factors/relative_pose3d.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Geometry>

#include "boxplus/errors.h"
#include "boxplus/manifolds/so3.h"
#include "boxplus/noise.h"

namespace boxplus {

namespace {

using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

Mat3 Skew(const Eigen::Vector3d& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// g2o convention with analytic Jacobians (see the header for the formulas).
class RelativePose3DG2oCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePose3DG2oCost(const Eigen::Matrix<double, 7, 1>& z, const Mat6& U) : U_(U) {
    tz_ = z.head<3>();
    qz_ = Eigen::Quaterniond(z[6], z[3], z[4], z[5]).normalized();
    RzT_ = qz_.conjugate().toRotationMatrix();
  }

  bool Evaluate(double const* const* x, double* residuals,
                double** jacobians) const override {
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
    using RowJ = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
    if (jacobians[0]) {
      Mat6 Jt;
      Jt.topLeftCorner<3, 3>() = -A;
      Jt.topRightCorner<3, 3>() = RzT_ * Skew(tij);
      Jt.bottomLeftCorner<3, 3>().setZero();
      Jt.bottomRightCorner<3, 3>() = -M * qij.toRotationMatrix().transpose();
      ToAmbient(U_ * Jt, xi + 3, Eigen::Map<RowJ>(jacobians[0]));
    }
    if (jacobians[1]) {
      Mat6 Jt;
      Jt.topLeftCorner<3, 3>() = A;
      Jt.topRightCorner<3, 3>().setZero();
      Jt.bottomLeftCorner<3, 3>().setZero();
      Jt.bottomRightCorner<3, 3>() = M;
      ToAmbient(U_ * Jt, xj + 3, Eigen::Map<RowJ>(jacobians[1]));
    }
    return true;
  }

 private:
  // Ambient Jacobian whose product with SE3's PlusJacobian is Jt: the rotation
  // columns are Jt_rot · 4Qᵀ (QᵀQ = I/4 for a unit quaternion).
  template <class Out>
  static void ToAmbient(const Mat6& Jt, const double* q, Out&& J) {
    double Qd[12];
    SO3Ops::PlusJacobian(q, Qd);
    const Eigen::Map<const Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> Q(Qd);
    J.template leftCols<3>() = Jt.leftCols<3>();
    J.template rightCols<4>() = 4.0 * Jt.rightCols<3>() * Q.transpose();
  }

  Eigen::Vector3d tz_;
  Eigen::Quaterniond qz_;
  Mat3 RzT_;
  Mat6 U_;
};

struct RelativePose3DFunctor {
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    Eigen::Matrix<T, 6, 1> e;
    RelativePose3DError(xi, xj, z.data(), convention, e.data());
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r_map(r);
    r_map = U.cast<T>() * e;
    return true;
  }
  Eigen::Matrix<double, 7, 1> z;
  Mat6 U;
  PoseErrorConvention convention;
};

Eigen::Matrix<double, 7, 1> Normalized(const Eigen::Matrix<double, 7, 1>& z) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 3D: measurement must be finite");
  const double n = z.tail<4>().norm();
  BOXPLUS_CHECK(n > 1e-12, "relative pose 3D: measured quaternion has zero norm");
  Eigen::Matrix<double, 7, 1> out = z;
  out.tail<4>() /= n;
  return out;
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeRelativePose3D(
    const Eigen::Matrix<double, 7, 1>& z, const Mat6& information,
    PoseErrorConvention convention) {
  if (convention == PoseErrorConvention::kLog) {
    return MakeRelativePose3DAutoDiff(z, information, convention);
  }
  const Mat6 U = SqrtInformationFromInformation(information, "relative pose 3D");
  return std::make_shared<RelativePose3DG2oCost>(Normalized(z), U);
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose3DAutoDiff(
    const Eigen::Matrix<double, 7, 1>& z, const Mat6& information,
    PoseErrorConvention convention) {
  const Mat6 U = SqrtInformationFromInformation(information, "relative pose 3D");
  return std::make_shared<ceres::AutoDiffCostFunction<RelativePose3DFunctor, 6, 7, 7>>(
      new RelativePose3DFunctor{Normalized(z), U, convention});
}

}  // namespace boxplus
