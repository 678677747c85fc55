// Gravity seen by an accelerometer (IMU) rigidly mounted with a camera: the
// MTKM paper's g_world2g_imu (Listing 2), with optional accelerometer scale
// and bias.
//
// Residual (3):  r = W (s · R(imu_from_rig) · R(world_from_rig)ᵀ · g_in_world + b − z)
//   (m/s²; WᵀW = Σ⁻¹, the NoiseModel). g_in_world is a constant: the vector the
//   accelerometer reads at rest, expressed in the world (board) frame — for a
//   levelled board whose z axis points down it is (0, 0, −9.81) in MTKM's
//   sign convention; give what your sensor reads.
// Parameter blocks: world_from_rig (SE3 7: the reference camera in the
// world/board frame, only its rotation enters), imu_from_rig (SE3 7: the
// reference camera in the IMU frame, only its rotation enters; its translation
// is not observable from gravity), and by model:
//   "rotation":   no more blocks (s = 1, b = 0)
//   "scale":      accel = [s]            (R¹)
//   "scale_bias": accel = [s, bx, by, bz] (R⁴, bias in the IMU frame, m/s²)
// Gravity alone never determines the rotation about the gravity axis (yaw);
// several board orientations (or other measurements) are needed.
#pragma once

#include <memory>
#include <string>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/se3.h"
#include "boxplus/noise.h"

namespace boxplus {

// kAccel: 0 rotation only, 1 scale, 4 scale and bias (the size of the accel block).
template <int kAccel>
class GravityFunctor {
 public:
  GravityFunctor(const Eigen::Vector3d& z, const Eigen::Matrix3d& W,
                 const Eigen::Vector3d& g_in_world)
      : z_(z), W_(W), g_in_world_(g_in_world) {}

  template <typename T>
  bool Predict(const T* world_from_rig, const T* imu_from_rig, const T* accel, T* r) const {
    const T g[3] = {T(g_in_world_[0]), T(g_in_world_[1]), T(g_in_world_[2])};
    T rig_from_world_q[4], g_in_rig[3], g_in_imu[3];
    QuatConjugate(world_from_rig + 3, rig_from_world_q);
    QuatRotatePoint(rig_from_world_q, g, g_in_rig);
    QuatRotatePoint(imu_from_rig + 3, g_in_rig, g_in_imu);
    for (int i = 0; i < 3; ++i) {
      T v = g_in_imu[i];
      if constexpr (kAccel >= 1) v = accel[0] * v;
      if constexpr (kAccel == 4) v = v + accel[1 + i];
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
      return std::make_shared<ceres::AutoDiffCostFunction<GravityFunctor, 3, 7, 7>>(f);
    } else {
      return std::make_shared<ceres::AutoDiffCostFunction<GravityFunctor, 3, 7, 7, kAccel>>(f);
    }
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Matrix3d W_;
  Eigen::Vector3d g_in_world_;
};

// model: "rotation", "scale" or "scale_bias"; `noise` of dimension 3 (m/s²).
// Throws boxplus::Error for another model, another noise dimension or
// non-finite input.
std::shared_ptr<ceres::CostFunction> MakeGravityFactor(const std::string& model,
                                                       const Eigen::Vector3d& z,
                                                       const NoiseModel& noise,
                                                       const Eigen::Vector3d& g_in_world);
// Size of the accel block of a gravity model (0, 1 or 4).
int GravityModelSize(const std::string& model);

}  // namespace boxplus
