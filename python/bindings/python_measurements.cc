// Python measurement functions inside Ceres.
//
// A Python `prepare(jacobians, new_point)` evaluates a whole group of
// measurements (errors f(Y) ⊟ z and their tangent Jacobians, by finite
// differences in Python/numpy) and returns arrays; C++ whitens them with each
// measurement's NoiseModel and serves Ceres through CachedCostFunction
// (cached_cost.h). Python errors raised there are kept in
// the current call's ErrorSlot (pending_error.h) and re-raised after Ceres
// returns.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/problem.h"
#include "cached_cost.h"
#include "factor.h"
#include "manifold_handle.h"
#include "pending_error.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

class PyResidualCache final : public ResidualCache {
 public:
  PyResidualCache(py::object prepare, int residual_size, std::vector<int> tangent_sizes,
                  std::string name)
      : prepare_(std::move(prepare)),
        m_(residual_size),
        tangent_(std::move(tangent_sizes)),
        name_(std::move(name)) {}
  ~PyResidualCache() override {
    py::gil_scoped_acquire gil;
    prepare_ = py::object();
    R_ = Array();
    J_.clear();
  }

  bool Prepare(bool jacobians, bool new_point) override {
    if (count_ == 0) return true;
    if (!new_point && have_residuals_ && (!jacobians || have_jacobians_)) return ok_;
    py::gil_scoped_acquire gil;
    if (new_point) have_residuals_ = have_jacobians_ = false;
    if (HasPendingError()) return ok_ = false;
    try {
      py::object result = prepare_(jacobians, new_point);
      if (!py::isinstance<py::tuple>(result) || py::len(result) != 2) {
        throw py::type_error(What() + ": prepare() must return a tuple (R, Js)");
      }
      py::tuple out = result;
      Array R = Array::ensure(out[0]);
      Check(R, {count_, m_}, "errors");
      std::vector<Array> J;
      if (jacobians) {
        py::list js = out[1];
        if (static_cast<int>(js.size()) != static_cast<int>(tangent_.size())) {
          throw py::value_error(What() + ": prepare() returned the wrong number of Jacobians");
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
    } catch (const py::builtin_exception& e) {
      e.set_error();
      StorePendingError(py::error_already_set());
      ok_ = false;
    } catch (const std::exception& e) {
      StorePendingCppError(e);
      ok_ = false;
    }
    return ok_;
  }
  const double* Error(int index) const override { return R_.data() + index * m_; }
  const double* TangentJacobian(int index, int slot) const override {
    return J_[slot].data() + index * m_ * tangent_[slot];
  }
  bool ok() const override { return ok_; }

  int Add() { return count_++; }
  int residual_size() const { return m_; }
  const std::vector<int>& tangent_sizes() const { return tangent_; }

 private:
  std::string What() const { return "measurement group '" + name_ + "'"; }
  void Check(const Array& a, std::vector<py::ssize_t> shape, const char* what) const {
    bool good = a && a.ndim() == static_cast<py::ssize_t>(shape.size());
    for (size_t i = 0; good && i < shape.size(); ++i) good = a.shape(i) == shape[i];
    if (!good)
      throw py::value_error(What() + ": prepare() returned " + what + " of the wrong shape");
  }

  py::object prepare_;
  int m_;
  std::vector<int> tangent_;
  std::string name_;
  int count_ = 0;
  Array R_;
  std::vector<Array> J_;
  bool ok_ = true, have_residuals_ = false, have_jacobians_ = false;
};

}  // namespace

void RegisterPythonMeasurements(py::module_& m) {
  py::class_<PyResidualCache, std::shared_ptr<PyResidualCache>>(m, "ResidualCache", R"doc(
A group of measurements evaluated together by a Python callable
``prepare(jacobians: bool, new_point: bool) -> (E, Js)`` with the errors E of
shape (N, m), not whitened, and, when jacobians is True, Js a list of
(N, m, tangent_size_k) arrays (their Jacobians). Each measurement's
NoiseModel whitens them in C++ (``cached_factor``).
)doc")
      .def(py::init([](py::object prepare, int residual_size, std::vector<int> tangent_sizes,
                       std::string name) {
             if (residual_size < 1) throw py::value_error("residual_size must be positive");
             for (int t : tangent_sizes) {
               if (t < 1) throw py::value_error("tangent sizes must be positive");
             }
             return std::make_shared<PyResidualCache>(std::move(prepare), residual_size,
                                                      std::move(tangent_sizes), std::move(name));
           }),
           py::arg("prepare"), py::arg("residual_size"), py::arg("tangent_sizes"),
           py::arg("name") = "");

  m.def(
      "cached_factor",
      [](const Problem& p, std::shared_ptr<PyResidualCache> cache, const std::vector<int>& ids,
         const NoiseModel& noise, const std::string& what) {
        if (ids.empty()) throw py::value_error(what + ": depends on no variable (ids is empty)");
        if (ids.size() != cache->tangent_sizes().size()) {
          throw py::value_error(what + ": wrong number of variables");
        }
        if (noise.dim() != cache->residual_size()) {
          throw py::value_error(what + ": noise of dimension " + std::to_string(noise.dim()) +
                                " for an error of " + std::to_string(cache->residual_size()) +
                                " entries");
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
        return Factor{
            std::make_shared<CachedCostFunction>(cache, index, cache->residual_size(), ms, noise),
            ids, noise};
      },
      py::arg("problem"), py::arg("cache"), py::arg("ids"), py::arg("noise"),
      py::arg("what") = "measurement",
      "The next measurement of a ResidualCache group, on variables ids, whitened by noise.");

  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem
      .def(
          "add_residual_cache",
          [](Problem& p, std::shared_ptr<PyResidualCache> cache) {
            p.AddEvaluationHook(
                [cache](bool jacobians, bool new_point) { cache->Prepare(jacobians, new_point); });
          },
          py::arg("cache"), "Registers a group so that it is evaluated before each solver step.")
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
