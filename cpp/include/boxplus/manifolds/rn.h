// Rⁿ: plain vectors, fixed size (RnOps<N>) or sized at run time (RnManifold).
//
// Ambient layout = tangent layout = the n coordinates.
//   x ⊞ δ = x + δ        y ⊟ x = y − x
#pragma once

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/manifolds/ops_manifold.h"

namespace boxplus {

template <int N>
struct RnOps {
  static constexpr int kAmbient = N;
  static constexpr int kTangent = N;
  template <typename T>
  static void Plus(const T* x, const T* delta, T* out) {
    for (int i = 0; i < N; ++i) out[i] = x[i] + delta[i];
  }
  template <typename T>
  static void Minus(const T* y, const T* x, T* out) {
    for (int i = 0; i < N; ++i) out[i] = y[i] - x[i];
  }
  static void PlusJacobian(const double*, double* J) {
    Eigen::Map<Eigen::Matrix<double, N, N>>(J).setIdentity();
  }
  static void MinusJacobian(const double*, double* J) {
    Eigen::Map<Eigen::Matrix<double, N, N>>(J).setIdentity();
  }
};

// Rⁿ with n chosen at run time (the Python layer's Rn(n)).
class RnManifold final : public ceres::Manifold {
 public:
  explicit RnManifold(int n) : n_(n) {
    BOXPLUS_CHECK(n >= 1, "Rn: dimension must be at least 1, got ", n);
  }
  int AmbientSize() const override { return n_; }
  int TangentSize() const override { return n_; }
  bool Plus(const double* x, const double* d, double* out) const override {
    for (int i = 0; i < n_; ++i) out[i] = x[i] + d[i];
    return true;
  }
  bool PlusJacobian(const double*, double* J) const override {
    Eigen::Map<Eigen::MatrixXd>(J, n_, n_).setIdentity();
    return true;
  }
  bool RightMultiplyByPlusJacobian(const double*, int num_rows, const double* ambient,
                                   double* tangent) const override {
    std::copy(ambient, ambient + num_rows * n_, tangent);
    return true;
  }
  bool Minus(const double* y, const double* x, double* out) const override {
    for (int i = 0; i < n_; ++i) out[i] = y[i] - x[i];
    return true;
  }
  bool MinusJacobian(const double*, double* J) const override {
    Eigen::Map<Eigen::MatrixXd>(J, n_, n_).setIdentity();
    return true;
  }

 private:
  int n_;
};

// A vector of Rⁿ (n fixed at construction).
class Rn {
 public:
  explicit Rn(int n = 0) : v_(Eigen::VectorXd::Zero(n)) {}
  explicit Rn(const Eigen::VectorXd& v) : v_(v) {
    BOXPLUS_CHECK(v.allFinite(), "Rn: vector has non-finite entries");
  }
  int dof() const { return static_cast<int>(v_.size()); }
  const Eigen::VectorXd& vec() const { return v_; }
  Rn boxplus(const Eigen::VectorXd& d) const {
    BOXPLUS_CHECK(d.size() == v_.size(), "Rn(", v_.size(), ") ⊞ δ: δ has size ", d.size());
    return Rn(Eigen::VectorXd(v_ + d));
  }
  Eigen::VectorXd boxminus(const Rn& x) const {
    BOXPLUS_CHECK(x.v_.size() == v_.size(), "Rn(", v_.size(), ") ⊟ Rn(", x.v_.size(),
                  "): sizes differ");
    return v_ - x.v_;
  }

 private:
  Eigen::VectorXd v_;
};

}  // namespace boxplus
