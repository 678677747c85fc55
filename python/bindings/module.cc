#include "bindings.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = "boxplus._core: C++ core of boxplus (manifolds, problem, solver).";
  m.attr("__version__") = BOXPLUS_VERSION;
  boxplus::python::RegisterErrors(m);
  boxplus::python::RegisterNoise(m);
  boxplus::python::RegisterManifolds(m);
  boxplus::python::RegisterValues(m);
  boxplus::python::RegisterProblem(m);
  boxplus::python::RegisterPythonMeasurements(m);
  boxplus::python::RegisterFactors(m);
  boxplus::python::RegisterPoseFactors(m);
  boxplus::python::RegisterSlam(m);
}
