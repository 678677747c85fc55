// A manifold whose ⊞/⊟ are Python functions on ambient vectors (a user's
// ManifoldValue), with Jacobians by central differences.
//
// Ceres must never see a failure it cannot handle: a false PlusJacobian
// fires a CHECK in Ceres' parameter_block.h and aborts the interpreter. So
// PlusJacobian always succeeds; when the user's ⊞ fails (raises, returns NaN,
// returns something that is not an ambient vector of the right size) the
// error is kept in the current ErrorSlot (pending_error.h), the Jacobian is
// filled with a harmless stand-in, and the evaluations that follow fail, so
// that the solve stops and re-raises the user's exception. Validate() checks
// ⊞ at a point before Ceres needs it (add_variable, set_value, solve).
#pragma once

#include <string>

#include <ceres/manifold.h>
#include <pybind11/pybind11.h>

namespace boxplus::python {

class PythonManifold final : public ceres::Manifold {
 public:
  PythonManifold(int ambient, int tangent, pybind11::object plus, pybind11::object minus,
                 std::string name);
  ~PythonManifold() override;
  int AmbientSize() const override { return a_; }
  int TangentSize() const override { return t_; }
  bool Plus(const double* x, const double* delta, double* out) const override;
  bool Minus(const double* y, const double* x, double* out) const override;
  // Central differences of δ ↦ x ⊞ δ at 0; never returns false (see above).
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // A left inverse of PlusJacobian (its pseudo-inverse), all that Ceres and
  // CachedCostFunction need, without stepping y off the manifold.
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // Raises (with the GIL held) the user's error, or a ValueError naming
  // `what`, if ⊞ or its Jacobian cannot be evaluated at x.
  void Validate(const double* x, const std::string& what) const;

 private:
  bool Call(const pybind11::object& f, const char* op, const double* u, int nu, const double* v,
            int nv, double* out, int nout) const;
  bool Jacobian(const double* x, double* jacobian) const;

  int a_, t_;
  pybind11::object plus_, minus_;
  std::string name_;
};

}  // namespace boxplus::python
