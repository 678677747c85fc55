// Gravity seen by an accelerometer (IMU) rigidly mounted with a camera: the
// MTKM paper's g_world2g_imu (Listing 2), with an accelerometer model that
// goes up to per-axis scale, bias and misalignment on raw counts.
//
// Residual (3):  r = W (T · R(imu_from_rig) · R(world_from_rig)ᵀ · g_in_world + b − z)
//   (z in the sensor's unit: m/s², or raw counts with T in counts per m/s² and
//   b in counts; WᵀW = Σ⁻¹, the NoiseModel). g_in_world is a constant: the
//   vector the accelerometer reads at rest, expressed in the world (board)
//   frame — for a levelled board whose z axis points down it is
//   (0, 0, −9.81) in MTKM's sign convention; give what your sensor reads.
// Parameter blocks: world_from_rig (SE3 7: the reference camera in the
// world/board frame, only its rotation enters), imu_from_rig (only its
// rotation enters: an SO3 block [q(x,y,z,w)] (4), or an SE3 block (7) whose
// translation no gravity reading determines), and by model the accel block:
//   "rotation":                      none            T = I, b = 0
//   "scale":                         [s]       (R¹)  T = s I
//   "scale_bias":                    [s, b]    (R⁴)  T = s I
//   "axis_scale_bias":               [sx, sy, sz, bx, by, bz]  (R⁶)  T = diag(s)
//   "axis_scale_bias_misalignment":  [sx, sy, sz, bx, by, bz, mxy, mxz, myz]  (R⁹)
//        T = diag(s) · U,  U = [[1, mxy, mxz], [0, 1, myz], [0, 0, 1]]
// The misalignment U is the upper-triangular non-orthogonality of the sensing
// axes (Tedaldi, Pretto & Menegatti, ICRA 2014, eq. 6): the IMU frame is taken
// with x on the x sensing axis and y in the plane of the x and y axes, so a
// full 3×3 T would repeat three directions of the rotation imu_from_rig.
// Gravity alone never determines the rotation about the gravity axis (yaw);
// several board orientations (or other measurements) are needed, and per-axis
// scales and biases need each axis to see gravity at several angles.
#pragma once

#include <memory>
#include <string>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/se3.h"
#include "boxplus/noise.h"

namespace boxplus {

// kAccel: the size of the accel block (0, 1, 4, 6 or 9, the models above);
// kImu: the size of the imu_from_rig block (4: SO3, 7: SE3).
template <int kAccel, int kImu = 7>
class GravityFunctor {
  static_assert(kAccel == 0 || kAccel == 1 || kAccel == 4 || kAccel == 6 || kAccel == 9,
                "accel block of 0, 1, 4, 6 or 9 numbers");
  static_assert(kImu == 4 || kImu == 7, "imu_from_rig is an SO3 (4) or SE3 (7) block");

 public:
  GravityFunctor(const Eigen::Vector3d& z, const Eigen::Matrix3d& W,
                 const Eigen::Vector3d& g_in_world)
      : z_(z), W_(W), g_in_world_(g_in_world) {}

  template <typename T>
  bool Predict(const T* world_from_rig, const T* imu_from_rig, const T* accel, T* r) const {
    const T g[3] = {T(g_in_world_[0]), T(g_in_world_[1]), T(g_in_world_[2])};
    T rig_from_world_q[4], g_in_rig[3], a[3];
    QuatConjugate(world_from_rig + 3, rig_from_world_q);
    QuatRotatePoint(rig_from_world_q, g, g_in_rig);
    QuatRotatePoint(imu_from_rig + (kImu - 4), g_in_rig, a);  // the quaternion ends the block
    if constexpr (kAccel == 9) {                              // U a, U upper unit triangular
      a[0] += accel[6] * a[1] + accel[7] * a[2];
      a[1] += accel[8] * a[2];
    }
    for (int i = 0; i < 3; ++i) {
      T v = a[i];
      if constexpr (kAccel == 1 || kAccel == 4) v = accel[0] * v;
      if constexpr (kAccel == 4) v = v + accel[1 + i];
      if constexpr (kAccel >= 6) v = accel[i] * v + accel[3 + i];
      r[i] = v - T(z_[i]);
    }
    WhitenInPlace<3>(W_, r);
    return true;
  }

  template <typename T>
  bool operator()(const T* world_from_rig, const T* imu_from_rig, T* r) const {
    return Predict(world_from_rig, imu_from_rig, static_cast<const T*>(nullptr), r);
  }
  template <typename T>
  bool operator()(const T* world_from_rig, const T* imu_from_rig, const T* accel, T* r) const {
    return Predict(world_from_rig, imu_from_rig, accel, r);
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Eigen::Vector3d& z,
                                                     const Eigen::Matrix3d& W,
                                                     const Eigen::Vector3d& g_in_world) {
    auto* f = new GravityFunctor(z, W, g_in_world);
    if constexpr (kAccel == 0) {
      return std::make_shared<ceres::AutoDiffCostFunction<GravityFunctor, 3, 7, kImu>>(f);
    } else {
      return std::make_shared<ceres::AutoDiffCostFunction<GravityFunctor, 3, 7, kImu, kAccel>>(f);
    }
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Matrix3d W_;
  Eigen::Vector3d g_in_world_;
};

// model: "rotation", "scale", "scale_bias", "axis_scale_bias" or
// "axis_scale_bias_misalignment"; `noise` of dimension 3 (the unit of z);
// imu_size: 4 when imu_from_rig is an SO3 variable, 7 for an SE3 one.
// Throws boxplus::Error for another model, noise dimension or imu_size, or
// non-finite input.
std::shared_ptr<ceres::CostFunction> MakeGravityFactor(const std::string& model,
                                                       const Eigen::Vector3d& z,
                                                       const NoiseModel& noise,
                                                       const Eigen::Vector3d& g_in_world,
                                                       int imu_size = 7);
// Size of the accel block of a gravity model (0, 1, 4, 6 or 9).
int GravityModelSize(const std::string& model);

}  // namespace boxplus
