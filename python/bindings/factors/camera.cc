// Bindings of the camera factors (cpp/include/boxplus/factors/camera/):
// projection of one point and of a whole board. Each is a function
// <factor>_factor(...) returning a Factor for Problem.add_factor; the factor
// whitens with `noise` (2-dim, pixels) and the problem keeps the same
// NoiseModel, so Problem.error(mid) is in pixels.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <iterator>
#include <string>
#include <vector>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/camera/board.h"
#include "boxplus/factors/camera/point_projection.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterCameraFactors(py::module_& m) {
  m.def("camera_model_size", &CameraModelSize, py::arg("model"),
        "Number of intrinsic parameters of a camera model.");
  m.def(
      "camera_model_names",
      [] {
        return std::vector<std::string>(std::begin(camera::kCameraModelNames),
                                        std::end(camera::kCameraModelNames));
      },
      "The camera models every camera term takes (camera/models.h), in C++'s order.");
  m.def(
      "point_projection_factor",
      [](const std::string& model, int intrinsics, int world_from_rig, int cam_from_rig,
         const Eigen::Vector2d& z, const NoiseModel& noise, const Eigen::Vector3d& p_in_world) {
        return Factor{MakePointProjectionFactor(model, z, noise, p_in_world),
                      {intrinsics, world_from_rig, cam_from_rig},
                      noise};
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("world_from_rig"), py::arg("cam_from_rig"),
      py::arg("z"), py::arg("noise"), py::arg("p_in_world"),
      "Projection r = W (π(k, cam_from_rig · world_from_rig⁻¹ · p_in_world) − z); see "
      "factors/camera/point_projection.h.");
  m.def(
      "board_factor",
      [](const std::string& model, int intrinsics, int world_from_rig, int cam_from_rig,
         const BoardPixels& z, const NoiseModel& noise, const BoardPoints& p_in_world) {
        return Factor{MakeBoardFactor(model, z, noise, p_in_world),
                      {intrinsics, world_from_rig, cam_from_rig},
                      noise};
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("world_from_rig"), py::arg("cam_from_rig"),
      py::arg("z"), py::arg("noise"), py::arg("p_in_world"),
      "All points of a board in one residual block: z (N, 2) pixels, p_in_world (N, 3), noise "
      "of one corner (2-dim); see factors/camera/board.h.");
}

}  // namespace boxplus::python
