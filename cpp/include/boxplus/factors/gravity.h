// Gravity seen by an accelerometer (IMU) rigidly mounted with a camera: the
// MTKM paper's g_world2g_imu (Listing 2), with optional accelerometer
// scale and bias.
//
// Residual (3):  r = W (s · R_imu_from_x · R_x2worldᵀ · g_in_world + b − z)
//   (m/s²; W = L⁻¹, LLᵀ = Σ). g_in_world is a constant: the vector the
//   accelerometer reads at rest, expressed in the world (board) frame — for a
//   levelled board whose z axis points down it is (0, 0, −9.81) in MTKM's
//   sign convention; give what your sensor reads.
// Parameter blocks: x2world (SE3 7: reference camera → world/board, only its
// rotation enters), x2imu (SE3 7: reference camera → IMU, only its rotation
// enters; its translation is not observable from gravity), and by model:
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

namespace boxplus {

// Mode: 0 rotation only, 1 scale, 4 scale and bias (the size of the accel block).
template <int kAccel>
class GravityFunctor {
 public:
  GravityFunctor(const Eigen::Vector3d& z, const Eigen::Matrix3d& sqrt_info,
                 const Eigen::Vector3d& g_in_world)
      : z_(z), W_(sqrt_info), g_(g_in_world) {}

  template <typename T>
  bool Predict(const T* x2world, const T* x2imu, const T* accel, T* r) const {
    const T g[3] = {T(g_[0]), T(g_[1]), T(g_[2])};
    T qinv[4], g_in_x[3], g_in_imu[3];
    QuatConjugate(x2world + 3, qinv);
    QuatRotatePoint(qinv, g, g_in_x);
    QuatRotatePoint(x2imu + 3, g_in_x, g_in_imu);
    T e[3];
    for (int i = 0; i < 3; ++i) {
      T v = g_in_imu[i];
      if (kAccel >= 1) v = accel[0] * v;
      if (kAccel == 4) v = v + accel[1 + i];
      e[i] = v - T(z_[i]);
    }
    for (int i = 0; i < 3; ++i) {
      r[i] = T(W_(i, 0)) * e[0] + T(W_(i, 1)) * e[1] + T(W_(i, 2)) * e[2];
    }
    return true;
  }

  template <typename T>
  bool operator()(const T* x2world, const T* x2imu, T* r) const {
    return Predict(x2world, x2imu, static_cast<const T*>(nullptr), r);
  }
  template <typename T>
  bool operator()(const T* x2world, const T* x2imu, const T* accel, T* r) const {
    return Predict(x2world, x2imu, accel, r);
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
  Eigen::Vector3d g_;
};

// model: "rotation", "scale" or "scale_bias"; throws boxplus::Error otherwise.
std::shared_ptr<ceres::CostFunction> MakeGravityFactor(const std::string& model,
                                                       const Eigen::Vector3d& z,
                                                       const Eigen::Matrix3d& sqrt_info,
                                                       const Eigen::Vector3d& g_in_world);
// Size of the accel block of a gravity model (0, 1 or 4).
int GravityModelSize(const std::string& model);

}  // namespace boxplus
