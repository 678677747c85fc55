// Bindings of the camera factors (cpp/include/boxplus/factors/camera/):
// projection of one point and of a whole board. Each is a method
// Problem.add_<factor>(...) returning the measurement id; the factor whitens
// with `noise` (2-dim, pixels) and the problem keeps the same NoiseModel, so
// Problem.error(mid) is in pixels.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../manifold_handle.h"
#include "boxplus/factors/camera/board.h"
#include "boxplus/factors/camera/point_projection.h"
#include "boxplus/problem.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterCameraFactors(py::module_& m) {
  m.def("camera_model_size", &CameraModelSize, py::arg("model"),
        "Number of intrinsic parameters of a camera model.");
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem.def(
      "add_pinhole_point",
      [](Problem& p, const std::string& model, int intrinsics, int world_from_rig, int cam_from_rig,
         const Eigen::Vector2d& z, const NoiseModel& noise, const Eigen::Vector3d& p_in_world,
         const std::string& name, const std::optional<LossHandle>& loss) {
        return p.AddMeasurement(MakePinholePointFactor(model, z, noise, p_in_world),
                                {intrinsics, world_from_rig, cam_from_rig}, noise,
                                loss ? loss->loss : nullptr, name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("world_from_rig"), py::arg("cam_from_rig"),
      py::arg("z"), py::arg("noise"), py::arg("p_in_world"), py::arg("name") = "",
      py::arg("loss") = py::none(),
      "Projection r = W (π(k, cam_from_rig · world_from_rig⁻¹ · p_in_world) − z); see "
      "factors/camera/point_projection.h.");
  problem.def(
      "add_pinhole_board",
      [](Problem& p, const std::string& model, int intrinsics, int world_from_rig, int cam_from_rig,
         const BoardPixels& z, const NoiseModel& noise, const BoardPoints& p_in_world,
         const std::string& name, const std::optional<LossHandle>& loss) {
        return p.AddMeasurement(MakePinholeBoardFactor(model, z, noise, p_in_world),
                                {intrinsics, world_from_rig, cam_from_rig}, noise,
                                loss ? loss->loss : nullptr, name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("world_from_rig"), py::arg("cam_from_rig"),
      py::arg("z"), py::arg("noise"), py::arg("p_in_world"), py::arg("name") = "",
      py::arg("loss") = py::none(),
      "All points of a board in one residual block: z (N, 2) pixels, p_in_world (N, 3), noise "
      "of one corner (2-dim); see factors/camera/board.h.");
}

}  // namespace boxplus::python
