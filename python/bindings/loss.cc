// Binding of the robust losses (boxplus/loss.h, the one loss parser).
#include <string>

#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/loss.h"
#include "manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
LossHandle MakeLossHandle(const std::string& name, double width) {
  return LossHandle{MakeLoss(name, width),
                    CanonicalLossName(name) + "(" + std::to_string(width) + ")"};
}
}  // namespace

void RegisterLoss(py::module_& m) {
  py::class_<LossHandle>(m, "Loss", "A robust loss ρ applied to ‖r‖² of one measurement.")
      .def(py::init(&MakeLossHandle), py::arg("name"), py::arg("width") = 1.0,
           "name: huber, cauchy, soft_l1, arctan, tukey or none (see loss_names()); width: "
           "where it departs from least squares (in whitened units, i.e. standard deviations).")
      .def("__repr__", [](const LossHandle& l) { return "Loss(" + l.description + ")"; });
  m.def("loss_names", &LossNames, "The accepted loss names.");
}

}  // namespace boxplus::python
