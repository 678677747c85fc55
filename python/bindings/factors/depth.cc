// Bindings of the depth-camera factors (cpp/include/boxplus/factors/depth/):
// Kinect-style disparity of a board point. The factor and the problem share
// one 1-dim NoiseModel (disparity units).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../manifold_handle.h"
#include "boxplus/factors/depth/disparity.h"
#include "boxplus/problem.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterDepthFactors(py::module_& m) {
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem.def(
      "add_disparity",
      [](Problem& p, int world_from_rig, int cam_from_rig, int disparity_params, double d,
         const NoiseModel& noise, const Eigen::Vector3d& p_in_world, const std::string& name,
         const std::optional<LossHandle>& loss) {
        return p.AddMeasurement(MakeDisparityFactor(d, noise, p_in_world),
                                {world_from_rig, cam_from_rig, disparity_params}, noise,
                                loss ? loss->loss : nullptr, name);
      },
      py::arg("world_from_rig"), py::arg("cam_from_rig"), py::arg("disparity_params"), py::arg("d"),
      py::arg("noise"), py::arg("p_in_world"), py::arg("name") = "", py::arg("loss") = py::none(),
      "Kinect-style disparity d = a / Z + b of a board point, noise 1-dim; see "
      "factors/depth/disparity.h.");
}

}  // namespace boxplus::python
