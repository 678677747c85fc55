#include "boxplus/factors/pose/prior.h"

#include <typeindex>
#include <unordered_map>

#include "boxplus/errors.h"
#include "boxplus/manifolds.h"

namespace boxplus {
namespace {

using Factory = std::shared_ptr<ceres::CostFunction> (*)(const Eigen::VectorXd& z,
                                                         const Eigen::MatrixXd& W);

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

std::shared_ptr<ceres::CostFunction> Rn(const Eigen::VectorXd& z, const Eigen::MatrixXd& W) {
  return std::make_shared<RnPrior>(z, W);
}

// The prior of each built-in manifold, by the manifold's (final) type.
const std::unordered_map<std::type_index, Factory>& PriorTable() {
  static const std::unordered_map<std::type_index, Factory> table = {
      {typeid(RnManifold), &Rn},
      {typeid(SO2Manifold), &Fixed<SO2Ops>},
      {typeid(SO3Manifold), &Fixed<SO3Ops>},
      {typeid(SE2Manifold), &Fixed<SE2Ops>},
      {typeid(SE3Manifold), &Fixed<SE3Ops>},
      {typeid(S2Manifold), &Fixed<S2Ops>},
  };
  return table;
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakePrior(const ceres::Manifold& manifold,
                                               const Eigen::VectorXd& z, const NoiseModel& noise,
                                               const std::string& what) {
  const int a = manifold.AmbientSize(), t = manifold.TangentSize();
  BOXPLUS_CHECK(z.size() == a, what, ": the observed value has ", z.size(),
                " ambient coordinates, the variable ", a);
  BOXPLUS_CHECK(noise.dim() == t, what, ": noise of dimension ", noise.dim(),
                " for a variable with ", t, " degrees of freedom");
  const auto& table = PriorTable();
  const auto it = table.find(typeid(manifold));
  if (it == table.end()) {
    throw Error(what + ": priors are available for Rn, SO2, SO3, SE2, SE3 and S2 variables");
  }
  return it->second(z, noise.sqrt_information());
}

}  // namespace boxplus
