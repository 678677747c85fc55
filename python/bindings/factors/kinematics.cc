// Bindings of the kinematics factors (cpp/include/boxplus/factors/kinematics/):
// a marker on a robot's hand seen by a camera, through known forward
// kinematics or a Denavit–Hartenberg chain with unknown link parameters. The
// problem keeps the same 2-dim NoiseModel the factor whitens with.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/kinematics/marker.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterKinematicsFactors(py::module_& m) {
  using Pose = Eigen::Matrix<double, 7, 1>;
  m.def(
      "marker_factor",
      [](const std::string& model, int intrinsics, int base_from_rig, int p_in_hand,
         int cam_from_rig, const Eigen::Vector2d& z, const NoiseModel& noise,
         const Pose& base_from_hand) {
        return Factor{MakeKnownKinematicsMarkerFactor(model, z, noise, base_from_hand),
                      {intrinsics, base_from_rig, p_in_hand, cam_from_rig},
                      noise};
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("base_from_rig"), py::arg("p_in_hand"),
      py::arg("cam_from_rig"), py::arg("z"), py::arg("noise"), py::arg("base_from_hand"),
      "Marker on a hand, base_from_hand from forward kinematics (constant); see "
      "factors/kinematics/marker.h.");
  m.def(
      "dh_marker_factor",
      [](const std::string& model, int intrinsics, int base_from_rig, int p_in_hand,
         int cam_from_rig, int dh, const Eigen::Vector2d& z, const NoiseModel& noise,
         const Eigen::VectorXd& joints, const Pose& base_from_chain, const Pose& flange_from_hand) {
        return Factor{
            MakeDHMarkerFactor(model, z, noise, joints, base_from_chain, flange_from_hand),
            {intrinsics, base_from_rig, p_in_hand, cam_from_rig, dh},
            noise};
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("base_from_rig"), py::arg("p_in_hand"),
      py::arg("cam_from_rig"), py::arg("dh"), py::arg("z"), py::arg("noise"), py::arg("joints"),
      py::arg("base_from_chain"), py::arg("flange_from_hand"),
      "Marker on a hand through a DH chain with unknown parameters dh (n×4: θ offset, d, a, α) "
      "from joint readings; see factors/kinematics/marker.h.");
}

}  // namespace boxplus::python
