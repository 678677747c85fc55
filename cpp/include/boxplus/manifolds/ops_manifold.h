// Adapters shared by every manifold: a ceres::Manifold built from an "Ops"
// struct, and a CRTP base for value types that store their ambient vector.
//
// An Ops struct describes one manifold S:
//   static constexpr int kAmbient, kTangent;
//   template <typename T> static void Plus(const T* x, const T* delta, T* out);
//   template <typename T> static void Minus(const T* y, const T* x, T* out);
//   static void PlusJacobian(const double* x, double* J);   // ambient × tangent
//   static void MinusJacobian(const double* x, double* J);  // tangent × ambient
// Jacobians are row-major, taken at δ = 0 and y = x respectively, as Ceres
// defines them, and analytic (tests compare them with finite differences).
// Plus/Minus are templates so that autodiff factors can call them on Jets.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>

namespace boxplus {

template <class Ops>
class OpsManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return Ops::kAmbient; }
  int TangentSize() const override { return Ops::kTangent; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Ops::Plus(x, delta, x_plus_delta);
    return true;
  }
  bool PlusJacobian(const double* x, double* jacobian) const override {
    Ops::PlusJacobian(x, jacobian);
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Ops::Minus(y, x, y_minus_x);
    return true;
  }
  bool MinusJacobian(const double* x, double* jacobian) const override {
    Ops::MinusJacobian(x, jacobian);
    return true;
  }
};

// Value types (SO3, SE3, ...) derive from this; it owns the ambient vector in
// exactly the layout the solver uses, so a value converts to and from solver
// storage by a plain copy.
template <class Derived, class Ops>
class ManifoldValue {
 public:
  static constexpr int kAmbient = Ops::kAmbient;
  static constexpr int kDof = Ops::kTangent;
  using Ambient = Eigen::Matrix<double, kAmbient, 1>;
  using Tangent = Eigen::Matrix<double, kDof, 1>;

  // x ⊞ δ.
  Derived boxplus(const Tangent& delta) const {
    Derived out;
    Ops::Plus(x_.data(), delta.data(), out.x_.data());
    return out;
  }
  // this ⊟ x.
  Tangent boxminus(const Derived& x) const {
    Tangent out;
    Ops::Minus(x_.data(), x.x_.data(), out.data());
    return out;
  }
  const Ambient& ambient() const { return x_; }
  const double* data() const { return x_.data(); }

 protected:
  Ambient x_;
};

}  // namespace boxplus
