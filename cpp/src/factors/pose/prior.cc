#include "boxplus/factors/pose/prior.h"

#include <typeindex>
#include <unordered_map>
#include <utility>
#include <vector>

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

// Rⁿ of run-time size, on some of its coordinates: r = W (x[i₁..iₘ] − z). All
// coordinates for a prior on the whole vector (MakePrior); a selection for
// MakeCoordinatePrior, e.g. a lens's distortion coefficients without its focal
// lengths.
class RnPrior final : public ceres::CostFunction {
 public:
  RnPrior(int size, std::vector<int> indices, const Eigen::VectorXd& z, const Eigen::MatrixXd& W)
      : indices_(std::move(indices)), z_(z), W_(W) {
    set_num_residuals(static_cast<int>(z.size()));
    mutable_parameter_block_sizes()->push_back(size);
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const int m = static_cast<int>(z_.size());
    Eigen::VectorXd e(m);
    for (int j = 0; j < m; ++j) e[j] = x[0][indices_[j]] - z_[j];
    Eigen::Map<Eigen::VectorXd>(residuals, m) = W_ * e;
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
          jacobians[0], m, parameter_block_sizes()[0]);
      J.setZero();
      for (int j = 0; j < m; ++j) J.col(indices_[j]) = W_.col(j);
    }
    return true;
  }

 private:
  std::vector<int> indices_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd W_;
};

std::shared_ptr<ceres::CostFunction> Rn(const Eigen::VectorXd& z, const Eigen::MatrixXd& W) {
  const int n = static_cast<int>(z.size());
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  return std::make_shared<RnPrior>(n, std::move(all), z, W);
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

std::shared_ptr<ceres::CostFunction> MakeCoordinatePrior(const ceres::Manifold& manifold,
                                                         const std::vector<int>& indices,
                                                         const Eigen::VectorXd& z,
                                                         const NoiseModel& noise,
                                                         const std::string& what) {
  BOXPLUS_CHECK(typeid(manifold) == typeid(RnManifold), what,
                ": a prior on some coordinates needs an Rn variable");
  const int n = manifold.AmbientSize();
  BOXPLUS_CHECK(!indices.empty(), what, ": no coordinates given");
  BOXPLUS_CHECK(z.size() == static_cast<Eigen::Index>(indices.size()), what, ": ", indices.size(),
                " coordinates and ", z.size(), " observed values");
  BOXPLUS_CHECK(noise.dim() == z.size(), what, ": noise of dimension ", noise.dim(), " for ",
                z.size(), " coordinates");
  std::vector<bool> seen(n, false);
  for (const int i : indices) {
    BOXPLUS_CHECK(i >= 0 && i < n, what, ": coordinate ", i, " of a variable with ", n);
    BOXPLUS_CHECK(!seen[i], what, ": coordinate ", i, " given twice");
    seen[i] = true;
  }
  return std::make_shared<RnPrior>(n, indices, z, noise.sqrt_information());
}

}  // namespace boxplus
