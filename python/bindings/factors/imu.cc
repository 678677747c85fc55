// Bindings of the IMU factors (cpp/include/boxplus/factors/imu/): gravity read
// by an accelerometer mounted with a camera. The problem keeps the same 3-dim
// NoiseModel (m/s²) the factor whitens with.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/imu/gravity.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterImuFactors(py::module_& m) {
  m.def("gravity_model_size", &GravityModelSize, py::arg("model"),
        "Size of the accelerometer block of a gravity model (rotation 0, scale 1, scale_bias 4, "
        "axis_scale_bias 6, axis_scale_bias_misalignment 9).");
  m.def(
      "gravity_factor",
      [](const std::string& model, int world_from_rig, int imu_from_rig, int accel,
         const Eigen::Vector3d& z, const NoiseModel& noise, const Eigen::Vector3d& g_in_world,
         int imu_size) {
        auto cost = MakeGravityFactor(model, z, noise, g_in_world, imu_size);
        std::vector<int> ids = {world_from_rig, imu_from_rig};
        if (GravityModelSize(model) > 0) ids.push_back(accel);
        return Factor{cost, ids, noise};
      },
      py::arg("model"), py::arg("world_from_rig"), py::arg("imu_from_rig"), py::arg("accel"),
      py::arg("z"), py::arg("noise"), py::arg("g_in_world"), py::arg("imu_size") = 7,
      "Gravity in the IMU: r = W (T R(imu_from_rig) R(world_from_rig)ᵀ g_in_world + b − z); "
      "accel ignored for model 'rotation'; imu_size 4 (SO3 imu_from_rig) or 7 (SE3); see "
      "factors/imu/gravity.h.");
}

}  // namespace boxplus::python
