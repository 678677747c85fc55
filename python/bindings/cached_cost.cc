#include "cached_cost.h"

#include <algorithm>

#include <Eigen/Core>

namespace boxplus {

CachedCostFunction::CachedCostFunction(std::shared_ptr<ResidualCache> cache, int index,
                                       int residual_size,
                                       std::vector<const ceres::Manifold*> manifolds,
                                       const NoiseModel& noise)
    : cache_(std::move(cache)),
      index_(index),
      manifolds_(std::move(manifolds)),
      W_(noise.sqrt_information()) {
  set_num_residuals(residual_size);
  for (const ceres::Manifold* m : manifolds_) {
    mutable_parameter_block_sizes()->push_back(m->AmbientSize());
  }
}

bool CachedCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  if (!cache_->ok()) return false;
  const int m = num_residuals();
  Eigen::Map<Eigen::VectorXd>(residuals, m).noalias() =
      W_ * Eigen::Map<const Eigen::VectorXd>(cache_->Error(index_), m);
  if (jacobians == nullptr) return true;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (size_t k = 0; k < manifolds_.size(); ++k) {
    if (jacobians[k] == nullptr) continue;
    const int a = manifolds_[k]->AmbientSize(), t = manifolds_[k]->TangentSize();
    Eigen::Map<const RowMajor> J_tan(cache_->TangentJacobian(index_, static_cast<int>(k)), m, t);
    Eigen::Map<RowMajor> J_amb(jacobians[k], m, a);
    RowMajor M(t, a);
    if (!manifolds_[k]->MinusJacobian(parameters[k], M.data())) return false;
    J_amb.noalias() = (W_ * J_tan) * M;
  }
  return true;
}

}  // namespace boxplus
