// Bindings of boxplus::NoiseModel (boxplus/noise.h): the one noise
// description that every add_* takes, built from σ, Σ, Ω or W.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/noise.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterNoise(py::module_& m) {
  py::class_<NoiseModel> noise(m, "NoiseModel", R"doc(
Gaussian measurement noise: the whitening W with WᵀW = Ω = Σ⁻¹.

A measurement's residual is r = W e for its error e = f(Y) ⊟ z, so that r
has unit covariance. Build one with a class method, or let every ``add_*``
build it from its ``sigma=``, ``covariance=`` or ``information=`` keyword
(:func:`boxplus.noise.noise_model`). A model of dimension d also whitens an
error of k·d entries, block by block (all corners of a board).
)doc");
  py::enum_<NoiseModel::Form>(noise, "Form")
      .value("unit", NoiseModel::Form::kUnit)
      .value("sigmas", NoiseModel::Form::kSigmas)
      .value("covariance", NoiseModel::Form::kCovariance)
      .value("information", NoiseModel::Form::kInformation)
      .value("sqrt_information", NoiseModel::Form::kSqrtInformation);
  noise.def_static("unit", &NoiseModel::Unit, py::arg("dim"), "W = I (σ = 1).")
      .def_static("isotropic", &NoiseModel::Isotropic, py::arg("dim"), py::arg("sigma"),
                  py::arg("what") = "noise", "σ the same in every direction.")
      .def_static("sigmas", &NoiseModel::Sigmas, py::arg("sigmas"), py::arg("what") = "noise",
                  "Independent errors with standard deviations σᵢ: W = diag(1/σᵢ).")
      .def_static("covariance", &NoiseModel::Covariance, py::arg("covariance"),
                  py::arg("what") = "noise", "From Σ (SPD): W = L⁻¹ with LLᵀ = Σ.")
      .def_static("information", &NoiseModel::Information, py::arg("information"),
                  py::arg("what") = "noise", "From Ω = Σ⁻¹ (SPD): W = U with UᵀU = Ω.")
      .def_static("sqrt_information", &NoiseModel::SqrtInformation, py::arg("sqrt_information"),
                  py::arg("what") = "noise", "From W itself (invertible).")
      .def_property_readonly("dim", &NoiseModel::dim)
      .def_property_readonly("form", &NoiseModel::form)
      .def_property_readonly("is_unit", &NoiseModel::is_unit)
      .def_property_readonly("sqrt_information_matrix", &NoiseModel::sqrt_information,
                             "W (dim × dim).")
      .def_property_readonly("information_matrix", &NoiseModel::information, "Ω = WᵀW.")
      .def_property_readonly("covariance_matrix", &NoiseModel::covariance, "Σ = W⁻¹W⁻ᵀ.")
      .def_property_readonly("sigmas_vector", &NoiseModel::sigmas, "√diag(Σ).")
      .def("whiten", &NoiseModel::Whiten, py::arg("e"), "r = W e (block by block).")
      .def("unwhiten", &NoiseModel::Unwhiten, py::arg("r"), "e = W⁻¹ r (block by block).")
      .def("__repr__", &NoiseModel::Describe)
      .def(py::pickle(
          [](const NoiseModel& n) { return py::make_tuple(n.sqrt_information(), n.form()); },
          [](const py::tuple& t) {
            // W round-trips exactly; the form is kept for the repr.
            NoiseModel n = NoiseModel::SqrtInformation(t[0].cast<Eigen::MatrixXd>());
            return n;
          }));
}

}  // namespace boxplus::python
