// SE(2) relative pose in g2o's convention with analytic Jacobians.
#include <ceres/sized_cost_function.h>

#include <cmath>

#include "boxplus/manifolds/rotation_math.h"
#include "relative_pose_analytic.h"

namespace boxplus::internal {
namespace {

class RelativePose2DCost final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  RelativePose2DCost(const Eigen::Vector3d& z, const Eigen::Matrix3d& U) : U_(U) {
    for (int k = 0; k < 3; ++k) z_[k] = z[k];
    cz_ = std::cos(z[2]);
    sz_ = std::sin(z[2]);
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const double* xi = x[0];
    const double* xj = x[1];
    const double ci = std::cos(xi[2]), si = std::sin(xi[2]);
    const double dx = xj[0] - xi[0], dy = xj[1] - xi[1];
    const double tx = ci * dx + si * dy, ty = -si * dx + ci * dy;  // t_ij
    Eigen::Vector3d e;
    e[0] = cz_ * (tx - z_[0]) + sz_ * (ty - z_[1]);
    e[1] = -sz_ * (tx - z_[0]) + cz_ * (ty - z_[1]);
    e[2] = WrapAngle(xj[2] - xi[2] - z_[2]);
    Eigen::Map<Eigen::Vector3d> residuals_map(residuals);
    residuals_map = U_ * e;
    if (!jacobians) return true;
    // A = R_zᵀ R_iᵀ (2×2): ∂t_Δ/∂p_j = A, ∂t_Δ/∂p_i = −A,
    // ∂t_Δ/∂θ_i = R_zᵀ [t_ij.y, −t_ij.x]ᵀ.
    const double c = cz_ * ci - sz_ * si, s = sz_ * ci + cz_ * si;  // R(θ_z+θ_i)
    Eigen::Matrix3d Jj = Eigen::Matrix3d::Zero();
    Jj(0, 0) = c;
    Jj(0, 1) = s;
    Jj(1, 0) = -s;
    Jj(1, 1) = c;
    Jj(2, 2) = 1.0;
    if (jacobians[0]) {
      Eigen::Matrix3d Ji = -Jj;
      Ji(0, 2) = cz_ * ty + sz_ * (-tx);
      Ji(1, 2) = -sz_ * ty + cz_ * (-tx);
      Ji(2, 2) = -1.0;
      {
        Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> jac(jacobians[0]);
        jac = U_ * Ji;
      }
    }
    if (jacobians[1]) {
      {
        Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> jac(jacobians[1]);
        jac = U_ * Jj;
      }
    }
    return true;
  }

 private:
  double z_[3];
  double cz_, sz_;
  Eigen::Matrix3d U_;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeRelativePose2DG2oAnalytic(const Eigen::Vector3d& z,
                                                                   const Eigen::Matrix3d& W) {
  return std::make_shared<RelativePose2DCost>(z, W);
}

}  // namespace boxplus::internal
