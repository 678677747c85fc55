// Registration functions of the extension module boxplus._core, one per
// area; module.cc calls them in dependency order.
#pragma once

#include <pybind11/pybind11.h>

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

}  // namespace boxplus::python
