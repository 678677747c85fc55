#include "bindings.h"
#include "native_log.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = "boxplus._core: C++ core of boxplus (manifolds, problem, solver).";
  m.attr("__version__") = BOXPLUS_VERSION;
  boxplus::python::RegisterErrors(m);
  boxplus::python::RegisterNoise(m);
  boxplus::python::RegisterLoss(m);
  boxplus::python::RegisterSolver(m);
  boxplus::python::RegisterManifolds(m);
  boxplus::python::RegisterPythonManifold(m);
  boxplus::python::RegisterValues(m);
  boxplus::python::RegisterProblem(m);
  boxplus::python::RegisterFactor(m);
  boxplus::python::RegisterPythonMeasurements(m);
  boxplus::python::RegisterCameraFactors(m);
  boxplus::python::RegisterKinematicsFactors(m);
  boxplus::python::RegisterJointFactors(m);
  boxplus::python::RegisterImuFactors(m);
  boxplus::python::RegisterDepthFactors(m);
  boxplus::python::RegisterPoseFactors(m);
  boxplus::python::RegisterSlam(m);
  boxplus::python::RegisterCertify(m);
  // Last: Ceres logs only inside solves, which cannot start before the module is loaded.
  boxplus::python::RegisterNativeLog(m);
}
