// Bindings of the pose-domain factors used by calibration: relative pose
// (compound ⊟) and a 3-D point seen in a sensor. Placeholder owned by package
// C (wp-slam), written here with the contract's signatures so that the
// calibration layer runs; C's version replaces it. The problem keeps the same
// NoiseModel the factor whitens with.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "boxplus/factors/point.h"
#include "boxplus/factors/relative_pose.h"
#include "boxplus/problem.h"
#include "../manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterPoseFactors(py::module_& m) {
  using Pose = Eigen::Matrix<double, 7, 1>;
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem.def(
      "add_relative_pose",
      [](Problem& p, int world_from_a, int world_from_b, const Pose& a_from_b,
         const NoiseModel& noise, const std::string& name, const LossHandle* loss) {
        const Eigen::Matrix<double, 6, 6> W = noise.Fixed<6>("relative pose factor");
        return p.AddMeasurement(MakeRelativePoseFactor(a_from_b, W), {world_from_a, world_from_b},
                                noise, loss ? loss->loss : nullptr, name);
      },
      py::arg("world_from_a"), py::arg("world_from_b"), py::arg("a_from_b"), py::arg("noise"),
      py::arg("name") = "", py::arg("loss") = nullptr,
      "r = W ((world_from_a⁻¹ · world_from_b) ⊟ a_from_b), tangent [δp, δθ]; see "
      "factors/relative_pose.h.");
  problem.def(
      "add_point",
      [](Problem& p, int world_from_rig, int cam_from_rig, int p_in_world_id,
         const Eigen::Vector3d& z, const NoiseModel& noise, const Eigen::Vector3d& p_in_world,
         const std::string& name, const LossHandle* loss) {
        const Eigen::Matrix3d W = noise.Fixed<3>("point factor");
        std::shared_ptr<ceres::LossFunction> l = loss ? loss->loss : nullptr;
        if (p_in_world_id >= 0) {
          return p.AddMeasurement(MakeLandmarkPointFactor(z, W),
                                  {world_from_rig, cam_from_rig, p_in_world_id}, noise, l, name);
        }
        return p.AddMeasurement(MakePointFactor(z, W, p_in_world), {world_from_rig, cam_from_rig},
                                noise, l, name);
      },
      py::arg("world_from_rig"), py::arg("cam_from_rig"), py::arg("p_in_world_id"), py::arg("z"),
      py::arg("noise"), py::arg("p_in_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "3-D point in the sensor frame: r = W (cam_from_rig · world_from_rig⁻¹ · p_in_world − z); "
      "p_in_world_id < 0 uses the constant p_in_world; see factors/point.h.");
}

}  // namespace boxplus::python
