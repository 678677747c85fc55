#include "boxplus/manifolds.h"

#include <Eigen/Core>

namespace boxplus {

ProductManifold::ProductManifold(std::vector<std::shared_ptr<const ceres::Manifold>> members)
    : members_(std::move(members)) {
  BOXPLUS_CHECK(!members_.empty(), "a compound needs at least one member");
  for (const auto& m : members_) {
    BOXPLUS_CHECK(m != nullptr, "a compound member is null");
    ambient_offsets_.push_back(ambient_size_);
    tangent_offsets_.push_back(tangent_size_);
    ambient_size_ += m->AmbientSize();
    tangent_size_ += m->TangentSize();
  }
}

bool ProductManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  for (size_t i = 0; i < members_.size(); ++i) {
    if (!members_[i]->Plus(x + ambient_offsets_[i], delta + tangent_offsets_[i],
                           x_plus_delta + ambient_offsets_[i])) {
      return false;
    }
  }
  return true;
}

bool ProductManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (size_t i = 0; i < members_.size(); ++i) {
    if (!members_[i]->Minus(y + ambient_offsets_[i], x + ambient_offsets_[i],
                            y_minus_x + tangent_offsets_[i])) {
      return false;
    }
  }
  return true;
}

namespace {
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace

bool ProductManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<RowMajor> J(jacobian, ambient_size_, tangent_size_);
  J.setZero();
  for (size_t i = 0; i < members_.size(); ++i) {
    const int a = members_[i]->AmbientSize(), t = members_[i]->TangentSize();
    RowMajor block(a, t);
    if (!members_[i]->PlusJacobian(x + ambient_offsets_[i], block.data())) {
      return false;
    }
    J.block(ambient_offsets_[i], tangent_offsets_[i], a, t) = block;
  }
  return true;
}

bool ProductManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<RowMajor> J(jacobian, tangent_size_, ambient_size_);
  J.setZero();
  for (size_t i = 0; i < members_.size(); ++i) {
    const int a = members_[i]->AmbientSize(), t = members_[i]->TangentSize();
    RowMajor block(t, a);
    if (!members_[i]->MinusJacobian(x + ambient_offsets_[i], block.data())) {
      return false;
    }
    J.block(tangent_offsets_[i], ambient_offsets_[i], t, a) = block;
  }
  return true;
}

std::shared_ptr<const ceres::Manifold> MakeManifold(const std::string& kind, int n) {
  if (kind == "Rn") return std::make_shared<RnManifold>(n);
  if (kind == "SO2") return std::make_shared<SO2Manifold>();
  if (kind == "SO3") return std::make_shared<SO3Manifold>();
  if (kind == "SE2") return std::make_shared<SE2Manifold>();
  if (kind == "SE3") return std::make_shared<SE3Manifold>();
  if (kind == "S2") return std::make_shared<S2Manifold>();
  throw Error("unknown manifold kind '" + kind + "' (expected Rn, SO2, SO3, SE2, SE3 or S2)");
}

}  // namespace boxplus
