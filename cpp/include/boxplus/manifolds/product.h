// Compound (Cartesian product) manifolds assembled at run time.
//
// Ambient vector = the members' ambient vectors concatenated; tangent vector =
// the members' tangent vectors concatenated in the same order; ⊞ and ⊟ act
// member-wise (MTKM paper, Sec. III-B). Plus/Minus Jacobians are block
// diagonal. Ceres 2.1's ProductManifold fixes its members at compile time;
// this one is what Python's make_compound needs.
#pragma once

#include <memory>
#include <vector>

#include <ceres/manifold.h>

namespace boxplus {

class ProductManifold final : public ceres::Manifold {
 public:
  explicit ProductManifold(std::vector<std::shared_ptr<const ceres::Manifold>> members);

  int AmbientSize() const override { return ambient_size_; }
  int TangentSize() const override { return tangent_size_; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  int num_members() const { return static_cast<int>(members_.size()); }
  const ceres::Manifold& member(int i) const { return *members_.at(i); }
  int ambient_offset(int i) const { return ambient_offsets_.at(i); }
  int tangent_offset(int i) const { return tangent_offsets_.at(i); }

 private:
  std::vector<std::shared_ptr<const ceres::Manifold>> members_;
  std::vector<int> ambient_offsets_, tangent_offsets_;
  int ambient_size_ = 0, tangent_size_ = 0;
};

}  // namespace boxplus
