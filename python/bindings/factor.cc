// Bindings of Factor (factor.h) and of the one path by which factors enter a
// problem and errors leave it: Problem.add_factor and Problem.errors.
#include "factor.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"
#include "pending_error.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterFactor(py::module_& m) {
  py::class_<Factor>(m, "Factor", R"doc(
A measurement built by one of the factor functions of ``boxplus._core``
(whitened residual r = W e, its variables, its NoiseModel), ready for
``Problem.add_factor``. Not picklable: a problem is copied by replaying the
public calls that built it (:mod:`boxplus._journal`).
)doc")
      .def_property_readonly("variables", [](const Factor& f) { return f.variables; })
      .def_property_readonly("noise", [](const Factor& f) { return f.noise; })
      .def_property_readonly("residual_size",
                             [](const Factor& f) { return f.cost->num_residuals(); })
      .def("__repr__", [](const Factor& f) {
        std::string ids;
        for (int v : f.variables) ids += (ids.empty() ? "" : ", ") + std::to_string(v);
        return "<boxplus.Factor: " + std::to_string(f.cost->num_residuals()) +
               " residuals on variables [" + ids + "], " + f.noise.Describe() + ">";
      });
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem
      .def(
          "add_factor",
          [](Problem& p, const Factor& f, const std::optional<LossHandle>& loss,
             const std::string& name) {
            return p.AddMeasurement(f.cost, f.variables, f.noise, loss ? loss->loss : nullptr,
                                    name);
          },
          py::arg("factor"), py::arg("loss") = py::none(), py::arg("name") = "",
          "Adds a factor; returns its measurement id. The problem keeps its NoiseModel, so "
          "error() and errors() are in the measurement's own units.")
      .def(
          "errors",
          [](Problem& p, const std::vector<int>& ids, bool whitened) {
            return RaisingPython([&] { return p.Errors(ids, whitened); });
          },
          py::arg("measurement_ids"), py::arg("whitened") = false,
          "Errors e = W⁻¹ r (or, whitened, the residuals r) of several measurements, "
          "concatenated in the order given, the measurements evaluated once.");
}

}  // namespace boxplus::python
