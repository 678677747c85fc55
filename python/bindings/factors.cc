// Bindings of the built-in C++ factors (autodiff functors): pinhole projection
// of a point or a whole board, hand markers through kinematics, gravity,
// relative pose, 3-D points and depth-to-disparity. Each is a method
// Problem.add_<factor>(...) returning the measurement id; the header of each
// factor (cpp/include/boxplus/factors/) states its residual, blocks and frames.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/factors/board.h"
#include "boxplus/factors/disparity.h"
#include "boxplus/factors/gravity.h"
#include "boxplus/factors/marker.h"
#include "boxplus/factors/pinhole.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
using Pose = Eigen::Matrix<double, 7, 1>;
using Points2 = PinholeBoardFunctor<camera::Pinhole>::Points2;
using Points3 = PinholeBoardFunctor<camera::Pinhole>::Points3;

std::shared_ptr<ceres::LossFunction> Loss(const LossHandle* loss) {
  return loss ? loss->loss : nullptr;
}
}  // namespace

void RegisterFactors(py::module_& m) {
  m.def("camera_model_size", &CameraModelSize, py::arg("model"),
        "Number of intrinsic parameters of a camera model.");
  m.def("gravity_model_size", &GravityModelSize, py::arg("model"),
        "Size of the accelerometer block of a gravity model (rotation 0, scale 1, scale_bias 4).");
  py::class_<Problem> problem = py::reinterpret_borrow<py::class_<Problem>>(m.attr("Problem"));
  problem.def(
      "add_pinhole_point",
      [](Problem& p, const std::string& model, int intrinsics, int x2world, int x2cam,
         const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info, const Eigen::Vector3d& p_world,
         const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(MakePinholePointFactor(model, z, sqrt_info, p_world),
                                {intrinsics, x2world, x2cam}, Loss(loss), name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("x2world"), py::arg("x2cam"), py::arg("z"),
      py::arg("sqrt_info"), py::arg("p_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "Pinhole projection r = W (π(k, x2cam ∘ x2world⁻¹ ∘ p_world) − z); see factors/pinhole.h.");
  problem.def(
      "add_pinhole_board",
      [](Problem& p, const std::string& model, int intrinsics, int x2world, int x2cam,
         const Points2& z, const Eigen::Matrix2d& sqrt_info, const Points3& p_world,
         const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(MakePinholeBoardFactor(model, z, sqrt_info, p_world),
                                {intrinsics, x2world, x2cam}, Loss(loss), name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("x2world"), py::arg("x2cam"), py::arg("z"),
      py::arg("sqrt_info"), py::arg("p_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "All points of a board in one residual block: z (N, 2) pixels, p_world (N, 3); see "
      "factors/board.h.");
  problem.def(
      "add_marker",
      [](Problem& p, const std::string& model, int intrinsics, int x2base, int p_in_hand,
         int x2cam, const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
         const Pose& hand2base, const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(MakeKnownKinematicsMarkerFactor(model, z, sqrt_info, hand2base),
                                {intrinsics, x2base, p_in_hand, x2cam}, Loss(loss), name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("x2base"), py::arg("p_in_hand"),
      py::arg("x2cam"), py::arg("z"), py::arg("sqrt_info"), py::arg("hand2base"),
      py::arg("name") = "", py::arg("loss") = nullptr,
      "Marker on a hand, hand2base from forward kinematics (constant); see factors/marker.h.");
  problem.def(
      "add_dh_marker",
      [](Problem& p, const std::string& model, int intrinsics, int x2base, int p_in_hand,
         int x2cam, int dh, const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
         const Eigen::VectorXd& joints, const Pose& base2chain, const Pose& flange2hand,
         const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(
            MakeDHMarkerFactor(model, z, sqrt_info, joints, base2chain, flange2hand),
            {intrinsics, x2base, p_in_hand, x2cam, dh}, Loss(loss), name);
      },
      py::arg("model"), py::arg("intrinsics"), py::arg("x2base"), py::arg("p_in_hand"),
      py::arg("x2cam"), py::arg("dh"), py::arg("z"), py::arg("sqrt_info"), py::arg("joints"),
      py::arg("base2chain"), py::arg("flange2hand"), py::arg("name") = "",
      py::arg("loss") = nullptr,
      "Marker on a hand through a DH chain with unknown parameters dh (n×4: θ offset, d, a, α) "
      "from joint readings; see factors/marker.h.");
  problem.def(
      "add_gravity",
      [](Problem& p, const std::string& model, int x2world, int x2imu, int accel,
         const Eigen::Vector3d& z, const Eigen::Matrix3d& sqrt_info,
         const Eigen::Vector3d& g_in_world, const std::string& name, const LossHandle* loss) {
        auto cost = MakeGravityFactor(model, z, sqrt_info, g_in_world);
        std::vector<int> ids = {x2world, x2imu};
        if (GravityModelSize(model) > 0) ids.push_back(accel);
        return p.AddMeasurement(cost, ids, Loss(loss), name);
      },
      py::arg("model"), py::arg("x2world"), py::arg("x2imu"), py::arg("accel"), py::arg("z"),
      py::arg("sqrt_info"), py::arg("g_in_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "Gravity in the IMU: r = W (s R_imu_x R_x2worldᵀ g + b − z); accel ignored for model "
      "'rotation'; see factors/gravity.h.");
  problem.def(
      "add_disparity",
      [](Problem& p, int x2world, int x2cam, int disparity_params, double d, double sigma,
         const Eigen::Vector3d& p_world, const std::string& name, const LossHandle* loss) {
        return p.AddMeasurement(MakeDisparityFactor(d, sigma, p_world),
                                {x2world, x2cam, disparity_params}, Loss(loss), name);
      },
      py::arg("x2world"), py::arg("x2cam"), py::arg("disparity_params"), py::arg("d"),
      py::arg("sigma"), py::arg("p_world"), py::arg("name") = "", py::arg("loss") = nullptr,
      "Kinect-style disparity d = a / Z + b of a board point; see factors/disparity.h.");
}

}  // namespace boxplus::python
