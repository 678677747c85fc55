// Bindings of the depth-camera factors (cpp/include/boxplus/factors/depth/):
// Kinect-style disparity of a board point. The factor and the problem share
// one 1-dim NoiseModel (disparity units).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/depth/disparity.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterDepthFactors(py::module_& m) {
  m.def(
      "disparity_factor",
      [](int world_from_rig, int cam_from_rig, int disparity_params, double d,
         const NoiseModel& noise, const Eigen::Vector3d& p_in_world) {
        return Factor{MakeDisparityFactor(d, noise, p_in_world),
                      {world_from_rig, cam_from_rig, disparity_params},
                      noise};
      },
      py::arg("world_from_rig"), py::arg("cam_from_rig"), py::arg("disparity_params"), py::arg("d"),
      py::arg("noise"), py::arg("p_in_world"),
      "Kinect-style disparity d = a / Z + b of a board point, noise 1-dim; see "
      "factors/depth/disparity.h.");
}

}  // namespace boxplus::python
