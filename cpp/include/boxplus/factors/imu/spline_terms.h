// The terms of camera–IMU calibration in motion on a spline trajectory
// (se3_spline.h: world_from_imu(t), world = the calibration target's frame),
// after Furgale, Rehder & Siegwart (IROS 2013, eqs. 5–8).
//
// Gyroscope (3):      r = W (ω_imu(t) + b_g − z)
//   blocks: the segment's 4 control points (SE3 7 each), b_g (R³)[, M (R⁶): the
//   reading M ω + b_g, M the gyroscope's scale and misalignment, below].
// Accelerometer (3):  r = W (R(t)ᵀ (a(t) − |g| ĝ) + b_a − z)
//   the specific force in the IMU frame; ĝ the direction of gravity in the
//   world (target) frame, a unit vector (S² block), |g| a constant (m/s²): at
//   rest the reading is −|g| R(t)ᵀ ĝ, "up".
//   blocks: 4 control points, b_a (R³), ĝ (S² 3)[, M (R⁶), as the gyroscope's
//   [, [r_y, r_z] (R⁶): the size effect, the y and z sensing elements at r_y, r_z from
//   the x element, each feeling e_iᵀ (f + α × r_i + ω × (ω × r_i))]].
// Reprojection (2):   r = W (π(k, cam_from_world(t_c + d) · p_in_world) − z)
//   a target corner seen by a camera at its own timestamp t_c; the IMU clock
//   reads t_c + d (d the time offset, a 1-vector block), the camera's pose is
//   world_from_imu(t_c + d) · imu_from_cam, π any camera model of
//   camera/models.h with intrinsics block k.
//   blocks: 4 control points, imu_from_cam (SE3 7), d (R¹), k (the model's size).
// Rolling shutter (2): the same at IMU time t_c + d + ℓ v, v the corner's measured
//   image row and ℓ the line delay (s per row; the frame's timestamp is the
//   readout of row 0): a rolling-shutter camera reads its rows one after the other
//   while the rig moves (Oth et al., CVPR 2013; Kalibr's rolling-shutter camera).
//   blocks: as above, then ℓ (R¹).
// Another IMU on the rig (3 each), at body_from_imu = [r, q_k] (SE3: its
// position r and orientation in the body IMU's frame, whose trajectory the
// spline is); with ω, α the body's angular velocity and acceleration:
//   gyroscope      r = W (R_kᵀ ω + b_g − z)
//   accelerometer  r = W (R_kᵀ (R(t)ᵀ (a(t) − |g| ĝ) + α × r + ω × (ω × r)) + b_a − z)
//   (the lever arm's tangential and centripetal acceleration: Furgale et al.'s
//   multi-IMU extension in Kalibr, Rehder et al., ICRA 2016).
//   blocks: 4 control points, body_from_imu (SE3 7), the bias (R³)[, ĝ (S² 3)]
//   [, d (R¹): its clock's offset, the sample read at body time t + d (Kalibr's
//   per-IMU time offset)].
// Times enter as u = (t − t_i)/Δt of the segment t_i the caller chose: for the
// gyroscope and accelerometer t is a sample's IMU time; for a reprojection,
// `t_rel` = t_c − t_i and u = (t_rel + d)/Δt, so d moves u (extrapolating
// past the segment when d moves a sample across a knot; se3_spline.h).
// Biases here are constant over the data (a random walk between bias knots is
// not modelled yet).
#pragma once

#include <memory>
#include <string>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/noise.h"

namespace boxplus {

// intrinsics: one more block, the IMU's scale and misalignment M (R⁶, [s_x, s_y, s_z,
// m_yx, m_zx, m_zy], the lower-triangular M = [[s_x, 0, 0], [m_yx, s_y, 0], [m_zx, m_zy,
// s_z]], Kalibr's scale-misalignment model): the reading is M ω + b_g, M f + b_a.
std::shared_ptr<ceres::CostFunction> MakeSplineGyroFactor(double u, double dt,
                                                          const Eigen::Vector3d& z,
                                                          const NoiseModel& noise,
                                                          bool intrinsics = false);

std::shared_ptr<ceres::CostFunction> MakeSplineAccelFactor(
    double u, double dt, const Eigen::Vector3d& z, const NoiseModel& noise,
    double gravity_magnitude = 9.81, bool intrinsics = false, bool size_effect = false);

// time_offset: one more block, the other IMU's time offset d (R¹; the sample's body
// time is its own + d), and u was computed with d = d0: u(d) = u + (d − d0)/Δt.
// intrinsics: one more block after it, the other IMU's own scale and misalignment M
// (R⁶, as MakeSplineGyroFactor's), applied in its own axes: M R_kᵀ ω + b_g.
std::shared_ptr<ceres::CostFunction> MakeSplineOffsetGyroFactor(
    double u, double dt, const Eigen::Vector3d& z, const NoiseModel& noise,
    bool time_offset = false, double d0 = 0.0, bool intrinsics = false);

std::shared_ptr<ceres::CostFunction> MakeSplineOffsetAccelFactor(
    double u, double dt, const Eigen::Vector3d& z, const NoiseModel& noise,
    double gravity_magnitude = 9.81, bool time_offset = false, double d0 = 0.0,
    bool intrinsics = false);

std::shared_ptr<ceres::CostFunction> MakeSplineReprojectionFactor(
    const std::string& model, double t_rel, double dt, const Eigen::Vector2d& z,
    const NoiseModel& noise, const Eigen::Vector3d& p_in_world, bool rolling_shutter = false);

}  // namespace boxplus
