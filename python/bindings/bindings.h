// Registration functions of the extension module boxplus._core, one per
// area; module.cc calls them in dependency order.
#pragma once

#include <pybind11/pybind11.h>

#include <algorithm>
#include <string>

#include <Eigen/Core>

namespace boxplus::python {

void RegisterErrors(pybind11::module_& m);
void RegisterNoise(pybind11::module_& m);
void RegisterLoss(pybind11::module_& m);
void RegisterSolver(pybind11::module_& m);
void RegisterManifolds(pybind11::module_& m);
void RegisterPythonManifold(pybind11::module_& m);
void RegisterValues(pybind11::module_& m);
void RegisterProblem(pybind11::module_& m);
void RegisterFactor(pybind11::module_& m);
void RegisterPythonMeasurements(pybind11::module_& m);
// The factors, one function per domain (bindings/factors/<domain>.cc).
void RegisterCameraFactors(pybind11::module_& m);
void RegisterKinematicsFactors(pybind11::module_& m);
void RegisterJointFactors(pybind11::module_& m);
void RegisterImuFactors(pybind11::module_& m);
void RegisterDepthFactors(pybind11::module_& m);
void RegisterPoseFactors(pybind11::module_& m);
void RegisterSlam(pybind11::module_& m);
void RegisterCertify(pybind11::module_& m);  // after RegisterSlam (adds to PoseGraph)

// todict() of a read-only result class: its public properties as plain Python values
// (boxplus/_plain.py), so that a result nested in another converts the same way
// whether it is bound here or a Python dataclass.
inline constexpr const char* kToDictDoc =
    "The properties as a dict of plain Python values (json.dumps takes it).";
inline pybind11::object PropertiesToDict(const pybind11::object& self) {
  return pybind11::module_::import("boxplus._plain").attr("properties_todict")(self);
}

// A value of kind T holding exactly the ambient numbers a, when they are a
// normalised value up to rounding (a stored value, pickled or copied): normalising
// them again (FromAmbient) can move the last bit. Other numbers are normalised as
// FromAmbient does; numbers that are not a value throw as it throws.
template <class T>
T FromAmbientExactly(const Eigen::VectorXd& a) {
  if (a.size() != T::kAmbient) {
    throw pybind11::value_error(std::to_string(a.size()) + " numbers for a value of ambient size " +
                                std::to_string(T::kAmbient));
  }
  T t = T::FromAmbient(a.data());
  double* x = const_cast<double*>(t.data());  // t's own storage
  if ((Eigen::Map<const Eigen::VectorXd>(x, a.size()) - a).cwiseAbs().maxCoeff() <= 1e-12) {
    std::copy(a.data(), a.data() + a.size(), x);
  }
  return t;
}

}  // namespace boxplus::python
