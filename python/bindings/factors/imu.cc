// Bindings of the IMU factors (cpp/include/boxplus/factors/imu/): gravity read
// by an accelerometer mounted with a camera. The problem keeps the same 3-dim
// NoiseModel (m/s²) the factor whitens with.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>
#include <vector>

#include "../bindings.h"
#include "../factor.h"
#include "boxplus/factors/imu/gravity.h"
#include "boxplus/factors/imu/se3_spline.h"
#include "boxplus/factors/imu/spline_terms.h"

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

  m.def(
      "spline_evaluate",
      [](const Eigen::Matrix<double, 4, 7, Eigen::RowMajor>& knots, double u, double dt) {
        const double* k[4] = {knots.row(0).data(), knots.row(1).data(), knots.row(2).data(),
                              knots.row(3).data()};
        Eigen::Vector3d p, v, a, w, alpha;
        Eigen::Vector4d q;
        spline::Evaluate(k, u, dt, p.data(), q.data(), v.data(), a.data(), w.data(), alpha.data());
        return py::make_tuple(p, q, v, a, w, alpha);
      },
      py::arg("knots"), py::arg("u"), py::arg("dt"),
      "(p, q, v, a, ω_body, α_body) of the R³ × SO(3) cubic B-spline segment whose 4 control "
      "points are the rows [p, q] of knots, at u (see factors/imu/se3_spline.h).");
  m.def(
      "spline_gyro_factor",
      [](const std::vector<int>& knots, int bias, double u, double dt, const Eigen::Vector3d& z,
         const NoiseModel& noise, std::optional<int> intrinsics) {
        if (knots.size() != 4) throw py::value_error("spline_gyro_factor: 4 control points");
        std::vector<int> ids = knots;
        ids.push_back(bias);
        if (intrinsics) ids.push_back(*intrinsics);
        return Factor{MakeSplineGyroFactor(u, dt, z, noise, intrinsics.has_value()), ids, noise};
      },
      py::arg("knots"), py::arg("bias"), py::arg("u"), py::arg("dt"), py::arg("z"),
      py::arg("noise"), py::arg("intrinsics") = py::none(),
      "r = W (M ω_imu(t) + b_g − z), M the scale and misalignment of the Rn(6) variable "
      "intrinsics (identity without); see factors/imu/spline_terms.h.");
  m.def(
      "spline_accel_factor",
      [](const std::vector<int>& knots, int bias, int gravity, double u, double dt,
         const Eigen::Vector3d& z, const NoiseModel& noise, double g, std::optional<int> intrinsics,
         std::optional<int> size_effect) {
        if (knots.size() != 4) throw py::value_error("spline_accel_factor: 4 control points");
        if (size_effect && !intrinsics)
          throw py::value_error("spline_accel_factor: size_effect needs intrinsics");
        std::vector<int> ids = knots;
        ids.push_back(bias);
        ids.push_back(gravity);
        if (intrinsics) ids.push_back(*intrinsics);
        if (size_effect) ids.push_back(*size_effect);
        return Factor{MakeSplineAccelFactor(u, dt, z, noise, g, intrinsics.has_value(),
                                            size_effect.has_value()),
                      ids, noise};
      },
      py::arg("knots"), py::arg("bias"), py::arg("gravity"), py::arg("u"), py::arg("dt"),
      py::arg("z"), py::arg("noise"), py::arg("g") = 9.81, py::arg("intrinsics") = py::none(),
      py::arg("size_effect") = py::none(),
      "r = W (M R(t)ᵀ (a(t) − g ĝ) + b_a − z); gravity: an S2 variable ĝ (the direction of "
      "gravity in the world frame), M as spline_gyro_factor's; size_effect: an Rn(6) [r_y, r_z] "
      "of the y and z sensing elements; see factors/imu/spline_terms.h.");
  m.def(
      "spline_offset_gyro_factor",
      [](const std::vector<int>& knots, int body_from_imu, int bias, double u, double dt,
         const Eigen::Vector3d& z, const NoiseModel& noise, std::optional<int> time_offset,
         double d0, std::optional<int> intrinsics) {
        if (knots.size() != 4) throw py::value_error("spline_offset_gyro_factor: 4 control points");
        std::vector<int> ids = knots;
        ids.push_back(body_from_imu);
        ids.push_back(bias);
        if (time_offset) ids.push_back(*time_offset);
        if (intrinsics) ids.push_back(*intrinsics);
        return Factor{MakeSplineOffsetGyroFactor(u, dt, z, noise, time_offset.has_value(), d0,
                                                 intrinsics.has_value()),
                      ids, noise};
      },
      py::arg("knots"), py::arg("body_from_imu"), py::arg("bias"), py::arg("u"), py::arg("dt"),
      py::arg("z"), py::arg("noise"), py::arg("time_offset") = py::none(), py::arg("d0") = 0.0,
      py::arg("intrinsics") = py::none(),
      "Another IMU's gyroscope: r = W (M R_kᵀ ω + b_g − z), with time_offset (an Rn(1) id) "
      "read at body time t + d, u computed with d = d0; M the scale and misalignment of the "
      "Rn(6) variable intrinsics (identity without); see factors/imu/spline_terms.h.");
  m.def(
      "spline_offset_accel_factor",
      [](const std::vector<int>& knots, int body_from_imu, int bias, int gravity, double u,
         double dt, const Eigen::Vector3d& z, const NoiseModel& noise, double g,
         std::optional<int> time_offset, double d0, std::optional<int> intrinsics) {
        if (knots.size() != 4)
          throw py::value_error("spline_offset_accel_factor: 4 control points");
        std::vector<int> ids = knots;
        ids.push_back(body_from_imu);
        ids.push_back(bias);
        ids.push_back(gravity);
        if (time_offset) ids.push_back(*time_offset);
        if (intrinsics) ids.push_back(*intrinsics);
        return Factor{MakeSplineOffsetAccelFactor(u, dt, z, noise, g, time_offset.has_value(), d0,
                                                  intrinsics.has_value()),
                      ids, noise};
      },
      py::arg("knots"), py::arg("body_from_imu"), py::arg("bias"), py::arg("gravity"), py::arg("u"),
      py::arg("dt"), py::arg("z"), py::arg("noise"), py::arg("g") = 9.81,
      py::arg("time_offset") = py::none(), py::arg("d0") = 0.0, py::arg("intrinsics") = py::none(),
      "Another IMU's accelerometer, with its lever arm: r = W (M R_kᵀ (R(t)ᵀ (a − g ĝ) + α × r + "
      "ω × (ω × r)) + b_a − z), M as spline_offset_gyro_factor's; see "
      "factors/imu/spline_terms.h.");
  m.def(
      "spline_reprojection_factor",
      [](const std::string& model, const std::vector<int>& knots, int imu_from_cam, int offset,
         int intrinsics, double t_rel, double dt, const Eigen::Vector2d& z, const NoiseModel& noise,
         const Eigen::Vector3d& p_in_world, std::optional<int> line_delay) {
        if (knots.size() != 4)
          throw py::value_error("spline_reprojection_factor: 4 control points");
        std::vector<int> ids = knots;
        ids.push_back(imu_from_cam);
        ids.push_back(offset);
        ids.push_back(intrinsics);
        if (line_delay) ids.push_back(*line_delay);
        return Factor{MakeSplineReprojectionFactor(model, t_rel, dt, z, noise, p_in_world,
                                                   line_delay.has_value()),
                      ids, noise};
      },
      py::arg("model"), py::arg("knots"), py::arg("imu_from_cam"), py::arg("offset"),
      py::arg("intrinsics"), py::arg("t_rel"), py::arg("dt"), py::arg("z"), py::arg("noise"),
      py::arg("p_in_world"), py::arg("line_delay") = py::none(),
      "A target corner seen at camera time t_c = t_i + t_rel: r = W (π(k, cam_from_world(t_c + "
      "d) p) − z); with line_delay (an R¹ variable ℓ, s per row) a rolling shutter: the "
      "pose at t_c + d + ℓ z_v. See factors/imu/spline_terms.h.");
}

}  // namespace boxplus::python
