// PythonManifold (python_manifold.h) and its factory make_python_manifold.
#include "python_manifold.h"

#include <pybind11/numpy.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "bindings.h"
#include "manifold_handle.h"
#include "pending_error.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace

PythonManifold::PythonManifold(int ambient, int tangent, py::object plus, py::object minus,
                               std::string name)
    : a_(ambient),
      t_(tangent),
      plus_(std::move(plus)),
      minus_(std::move(minus)),
      name_(std::move(name)) {}

PythonManifold::~PythonManifold() {
  py::gil_scoped_acquire gil;
  plus_ = py::object();
  minus_ = py::object();
}

bool PythonManifold::Plus(const double* x, const double* delta, double* out) const {
  py::gil_scoped_acquire gil;
  return Call(plus_, "⊞ (boxplus)", x, a_, delta, t_, out, a_);
}

bool PythonManifold::Minus(const double* y, const double* x, double* out) const {
  py::gil_scoped_acquire gil;
  return Call(minus_, "⊟ (boxminus)", y, a_, x, a_, out, t_);
}

bool PythonManifold::Jacobian(const double* x, double* jacobian) const {
  const double h = 1e-6;
  std::vector<double> d(t_, 0.0), xp(a_), xm(a_);
  for (int j = 0; j < t_; ++j) {
    d[j] = h;
    if (!Plus(x, d.data(), xp.data())) return false;
    d[j] = -h;
    if (!Plus(x, d.data(), xm.data())) return false;
    d[j] = 0.0;
    for (int i = 0; i < a_; ++i) jacobian[i * t_ + j] = (xp[i] - xm[i]) / (2 * h);
  }
  return true;
}

bool PythonManifold::PlusJacobian(const double* x, double* jacobian) const {
  if (Jacobian(x, jacobian)) return true;
  // The error is pending (Call stored it); the stand-in [I; 0] keeps Ceres'
  // bookkeeping finite until the failing evaluation stops the solve.
  std::fill(jacobian, jacobian + a_ * t_, 0.0);
  for (int k = 0; k < std::min(a_, t_); ++k) jacobian[k * t_ + k] = 1.0;
  return true;
}

bool PythonManifold::MinusJacobian(const double* x, double* jacobian) const {
  RowMatrix P(a_, t_);
  if (!Jacobian(x, P.data())) return false;
  const Eigen::MatrixXd PtP = P.transpose() * P;
  Eigen::Map<RowMatrix> M(jacobian, t_, a_);
  M = PtP.ldlt().solve(P.transpose());
  return M.allFinite();
}

void PythonManifold::Validate(const double* x, const std::string& what) const {
  ErrorScope scope;
  std::vector<double> y(a_), d(t_, 0.0);
  RowMatrix P(a_, t_);
  bool ok = Call(plus_, "⊞ (boxplus)", x, a_, d.data(), t_, y.data(), a_) && Jacobian(x, P.data());
  if (auto e = scope.slot().Take()) {
    if (e->matches(PyExc_Exception)) {
      // Name the variable without losing the user's exception and traceback.
      py::object v = e->value();
      if (py::hasattr(v, "add_note")) {
        v.attr("add_note")(what + ": the " + name_ + " manifold's ⊞ failed here");
      }
    }
    throw std::move(*e);
  }
  if (!ok || !P.allFinite()) {
    throw py::value_error(what + ": the " + name_ + " manifold's ⊞ has a non-finite Jacobian");
  }
}

bool PythonManifold::Call(const py::object& f, const char* op, const double* u, int nu,
                          const double* v, int nv, double* out, int nout) const {
  if (HasPendingError()) return false;
  try {
    Array U(nu), V(nv);
    std::copy(u, u + nu, U.mutable_data());
    std::copy(v, v + nv, V.mutable_data());
    py::object r = f(U, V);
    Array a = Array::ensure(r);
    if (!a || a.ndim() > 1 || a.size() != nout) {
      throw py::value_error("the " + name_ + " manifold's " + op + " returned " +
                            std::string(py::str(py::type::of(r).attr("__name__"))) + " " +
                            std::string(py::repr(r)).substr(0, 200) + "; expected " +
                            std::to_string(nout) + " numbers");
    }
    const double* d = a.data();
    if (!std::all_of(d, d + nout, [](double z) { return std::isfinite(z); })) {
      throw py::value_error("the " + name_ + " manifold's " + op + " returned non-finite numbers " +
                            std::string(py::repr(r)));
    }
    std::copy(d, d + nout, out);
    return true;
  } catch (py::error_already_set& e) {
    StorePendingError(std::move(e));
  } catch (const py::builtin_exception& e) {
    e.set_error();
    StorePendingError(py::error_already_set());
  } catch (const std::exception& e) {
    StorePendingCppError(e);
  }
  return false;
}

void RegisterPythonManifold(py::module_& m) {
  m.def(
      "make_python_manifold",
      [](int ambient, int tangent, py::object plus, py::object minus, const std::string& name) {
        if (ambient < 1 || tangent < 1) throw py::value_error("sizes must be positive");
        if (tangent > ambient) {
          throw py::value_error("a manifold's tangent size cannot exceed its ambient size");
        }
        return ManifoldHandle{std::make_shared<PythonManifold>(ambient, tangent, plus, minus, name),
                              name};
      },
      py::arg("ambient_size"), py::arg("tangent_size"), py::arg("plus"), py::arg("minus"),
      py::arg("name") = "Python",
      "A manifold whose ⊞ (plus(x, δ)) and ⊟ (minus(y, x)) are Python functions on "
      "ambient vectors.");
}

}  // namespace boxplus::python
