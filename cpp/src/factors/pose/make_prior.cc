#include "boxplus/factors/pose/make_prior.h"

#include <ceres/dynamic_autodiff_cost_function.h>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/manifolds.h"

namespace boxplus {
namespace {

template <class Ops>
std::shared_ptr<ceres::CostFunction> Fixed(const Eigen::VectorXd& z, const Eigen::MatrixXd& W) {
  return PriorFunctor<Ops>::Create(z, W);
}

// Rⁿ of run-time size: r = W (x − z).
class RnPrior final : public ceres::CostFunction {
 public:
  RnPrior(const Eigen::VectorXd& z, const Eigen::MatrixXd& W) : z_(z), W_(W) {
    set_num_residuals(static_cast<int>(z.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(z.size()));
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const int n = static_cast<int>(z_.size());
    Eigen::Map<Eigen::VectorXd>(residuals, n) =
        W_ * (Eigen::Map<const Eigen::VectorXd>(x[0], n) - z_);
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[0], n, n) = W_;
    }
    return true;
  }

 private:
  Eigen::VectorXd z_;
  Eigen::MatrixXd W_;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakePrior(const ceres::Manifold& manifold,
                                               const Eigen::VectorXd& z, const NoiseModel& noise,
                                               const std::string& what) {
  const Eigen::MatrixXd& W = noise.sqrt_information();
  const int a = manifold.AmbientSize(), t = manifold.TangentSize();
  BOXPLUS_CHECK(z.size() == a, what, ": the observed value has ", z.size(),
                " ambient coordinates, the variable ", a);
  BOXPLUS_CHECK(noise.dim() == t, what, ": noise of dimension ", noise.dim(),
                " for a variable with ", t, " degrees of freedom");
  if (dynamic_cast<const RnManifold*>(&manifold)) {
    return std::make_shared<RnPrior>(z, W);
  }
  if (dynamic_cast<const SO2Manifold*>(&manifold)) return Fixed<SO2Ops>(z, W);
  if (dynamic_cast<const SO3Manifold*>(&manifold)) return Fixed<SO3Ops>(z, W);
  if (dynamic_cast<const SE2Manifold*>(&manifold)) return Fixed<SE2Ops>(z, W);
  if (dynamic_cast<const SE3Manifold*>(&manifold)) return Fixed<SE3Ops>(z, W);
  if (dynamic_cast<const S2Manifold*>(&manifold)) return Fixed<S2Ops>(z, W);
  throw Error(what + ": priors are available for Rn, SO2, SO3, SE2, SE3 and S2 variables");
}

}  // namespace boxplus
