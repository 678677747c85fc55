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

}  // namespace boxplus::python
