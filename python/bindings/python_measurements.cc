// Python measurement functions and Python-defined manifolds inside Ceres.
//
// - ResidualCache: a Python `prepare(jacobians, new_point)` evaluates a whole
//   group of measurements (residuals and tangent Jacobians, by finite
//   differences in Python/numpy) and returns arrays; C++ serves Ceres from
//   them through CachedCostFunction (see boxplus/cached_cost.h).
// - PythonManifold: ⊞/⊟ written in Python, Jacobians by central differences.
// - Robust losses by name.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <ceres/loss_function.h>

#include <Eigen/Cholesky>

#include "bindings.h"
#include "boxplus/cached_cost.h"
#include "boxplus/loss.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"
#include "pending_error.h"

namespace py = pybind11;

namespace boxplus::python {

namespace {
std::unique_ptr<py::error_already_set>& Slot() {
  static std::unique_ptr<py::error_already_set> slot;
  return slot;
}
}  // namespace

void StorePendingError(py::error_already_set&& e) {
  // Keep the first error: later ones are usually its consequences.
  if (!Slot()) Slot() = std::make_unique<py::error_already_set>(std::move(e));
}
bool HasPendingError() { return Slot() != nullptr; }
std::unique_ptr<py::error_already_set> TakePendingError() { return std::move(Slot()); }

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

class PyResidualCache final : public ResidualCache {
 public:
  PyResidualCache(py::object prepare, int residual_size, std::vector<int> tangent_sizes)
      : prepare_(std::move(prepare)), m_(residual_size), tangent_(std::move(tangent_sizes)) {}

  bool Prepare(bool jacobians, bool new_point) override {
    if (count_ == 0) return true;
    if (!new_point && have_residuals_ && (!jacobians || have_jacobians_)) return ok_;
    py::gil_scoped_acquire gil;
    if (new_point) have_residuals_ = have_jacobians_ = false;
    if (HasPendingError()) return ok_ = false;
    try {
      py::tuple out = prepare_(jacobians, new_point);
      Array R = Array::ensure(out[0]);
      Check(R, {count_, m_}, "residuals");
      std::vector<Array> J;
      if (jacobians) {
        py::list js = out[1];
        if (static_cast<int>(js.size()) != static_cast<int>(tangent_.size())) {
          throw py::value_error("prepare() returned the wrong number of Jacobians");
        }
        for (size_t k = 0; k < tangent_.size(); ++k) {
          J.push_back(Array::ensure(js[k]));
          Check(J.back(), {count_, m_, tangent_[k]}, "Jacobian");
        }
      }
      R_ = std::move(R);
      if (jacobians) J_ = std::move(J);
      have_residuals_ = true;
      have_jacobians_ = jacobians;
      ok_ = true;
    } catch (py::error_already_set& e) {
      StorePendingError(std::move(e));
      ok_ = false;
    } catch (const std::exception& e) {
      py::set_error(PyExc_RuntimeError, e.what());
      StorePendingError(py::error_already_set());
      ok_ = false;
    }
    return ok_;
  }
  const double* Residual(int index) const override { return R_.data() + index * m_; }
  const double* TangentJacobian(int index, int slot) const override {
    return J_[slot].data() + index * m_ * tangent_[slot];
  }
  bool ok() const override { return ok_; }

  int Add() { return count_++; }
  int residual_size() const { return m_; }
  const std::vector<int>& tangent_sizes() const { return tangent_; }

 private:
  static void Check(const Array& a, std::vector<py::ssize_t> shape, const char* what) {
    bool good = a && a.ndim() == static_cast<py::ssize_t>(shape.size());
    for (size_t i = 0; good && i < shape.size(); ++i) good = a.shape(i) == shape[i];
    if (!good) throw py::value_error(std::string("prepare() returned ") + what + " of the wrong shape");
  }

  py::object prepare_;
  int m_;
  std::vector<int> tangent_;
  int count_ = 0;
  Array R_;
  std::vector<Array> J_;
  bool ok_ = true, have_residuals_ = false, have_jacobians_ = false;
};

// ⊞/⊟ given as Python functions on ambient vectors.
class PythonManifold final : public ceres::Manifold {
 public:
  PythonManifold(int ambient, int tangent, py::object plus, py::object minus)
      : a_(ambient), t_(tangent), plus_(std::move(plus)), minus_(std::move(minus)) {}
  ~PythonManifold() override {
    py::gil_scoped_acquire gil;
    plus_ = py::object();
    minus_ = py::object();
  }
  int AmbientSize() const override { return a_; }
  int TangentSize() const override { return t_; }

  bool Plus(const double* x, const double* delta, double* out) const override {
    py::gil_scoped_acquire gil;
    return Call(plus_, x, a_, delta, t_, out, a_);
  }
  bool Minus(const double* y, const double* x, double* out) const override {
    py::gil_scoped_acquire gil;
    return Call(minus_, y, a_, x, a_, out, t_);
  }
  // Central differences of δ ↦ x ⊞ δ at 0.
  bool PlusJacobian(const double* x, double* jacobian) const override {
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
  // The pseudo-inverse of PlusJacobian: a left inverse, which is all that
  // Ceres and CachedCostFunction need, without stepping y off the manifold.
  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> P(a_, t_);
    if (!PlusJacobian(x, P.data())) return false;
    const Eigen::MatrixXd PtP = P.transpose() * P;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> M(
        jacobian, t_, a_);
    M = PtP.ldlt().solve(P.transpose());
    return M.allFinite();
  }

 private:
  static bool Call(const py::object& f, const double* u, int nu, const double* v, int nv,
                   double* out, int nout) {
    if (HasPendingError()) return false;
    try {
      Array U(nu), V(nv);
      std::copy(u, u + nu, U.mutable_data());
      std::copy(v, v + nv, V.mutable_data());
      Array r = Array::ensure(f(U, V));
      if (!r || r.size() != nout) {
        throw py::value_error("a Python manifold's ⊞/⊟ returned " +
                              std::to_string(r ? r.size() : 0) + " numbers, expected " +
                              std::to_string(nout));
      }
      std::copy(r.data(), r.data() + nout, out);
      return true;
    } catch (py::error_already_set& e) {
      StorePendingError(std::move(e));
      return false;
    }
  }
  int a_, t_;
  py::object plus_, minus_;
};

LossHandle MakeLossHandle(const std::string& name, double width) {
  return LossHandle{MakeLoss(name, width), CanonicalLossName(name) + "(" + std::to_string(width) + ")"};
}

}  // namespace

void RegisterPythonMeasurements(py::module_& m) {
  py::class_<LossHandle>(m, "Loss", "A robust loss ρ applied to ‖r‖² of one measurement.")
      .def(py::init(&MakeLossHandle), py::arg("name"), py::arg("width") = 1.0,
           "name: huber, cauchy, soft_l1, arctan, tukey or none; width: where it "
           "departs from least squares (in whitened units, i.e. standard deviations).")
      .def("__repr__", [](const LossHandle& l) { return "Loss(" + l.description + ")"; });

  py::class_<PyResidualCache, std::shared_ptr<PyResidualCache>>(m, "ResidualCache", R"doc(
A group of measurements evaluated together by a Python callable
``prepare(jacobians: bool, new_point: bool) -> (R, Js)`` with R of shape (N, m)
and, when jacobians is True, Js a list of (N, m, tangent_size_k) arrays.
)doc")
      .def(py::init<py::object, int, std::vector<int>>(), py::arg("prepare"),
           py::arg("residual_size"), py::arg("tangent_sizes"));

  m.def(
      "make_python_manifold",
      [](int ambient, int tangent, py::object plus, py::object minus, const std::string& name) {
        if (ambient < 1 || tangent < 1) throw py::value_error("sizes must be positive");
        return ManifoldHandle{std::make_shared<PythonManifold>(ambient, tangent, plus, minus),
                              name};
      },
      py::arg("ambient_size"), py::arg("tangent_size"), py::arg("plus"), py::arg("minus"),
      py::arg("name") = "Python",
      "A manifold whose ⊞ (plus(x, δ)) and ⊟ (minus(y, x)) are Python functions on "
      "ambient vectors.");

  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem
      .def(
          "add_residual_cache",
          [](Problem& p, std::shared_ptr<PyResidualCache> cache) {
            p.AddEvaluationHook([cache](bool jacobians, bool new_point) {
              cache->Prepare(jacobians, new_point);
            });
          },
          py::arg("cache"), "Registers a group so that it is evaluated before each solver step.")
      .def(
          "add_cached_measurement",
          [](Problem& p, std::shared_ptr<PyResidualCache> cache, const std::vector<int>& ids,
             const LossHandle* loss, const std::string& name) {
            const std::string what = "measurement '" + name + "'";
            if (ids.size() != cache->tangent_sizes().size()) {
              throw py::value_error(what + ": wrong number of variables");
            }
            std::vector<const ceres::Manifold*> ms;
            for (size_t k = 0; k < ids.size(); ++k) {
              const ceres::Manifold& mf = p.manifold(ids[k]);  // raises IndexError
              if (mf.TangentSize() != cache->tangent_sizes()[k]) {
                throw py::value_error(what + ": variable " + std::to_string(ids[k]) +
                                      " has the wrong number of degrees of freedom");
              }
              ms.push_back(&mf);
            }
            const int index = cache->Add();
            auto cost = std::make_shared<CachedCostFunction>(cache, index, cache->residual_size(),
                                                             ms);
            return p.AddMeasurement(cost, ids, loss ? loss->loss : nullptr, name);
          },
          py::arg("cache"), py::arg("ids"), py::arg("loss") = nullptr, py::arg("name") = "")
      .def(
          "values",
          [](const Problem& p, const std::vector<int>& ids) {
            if (ids.empty()) throw py::value_error("values(ids): ids is empty");
            const int a = p.manifold(ids[0]).AmbientSize();
            Array out({static_cast<py::ssize_t>(ids.size()), static_cast<py::ssize_t>(a)});
            double* o = out.mutable_data();
            for (size_t i = 0; i < ids.size(); ++i) {
              if (p.manifold(ids[i]).AmbientSize() != a) {
                throw py::value_error("values(ids): variables of different sizes");
              }
              const double* v = p.value(ids[i]);
              std::copy(v, v + a, o + i * a);
            }
            return out;
          },
          py::arg("ids"), "Ambient values of several same-sized variables, one per row (a copy).");
}

}  // namespace boxplus::python
