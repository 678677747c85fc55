// A 3-D point measured in a sensor frame (point-to-point: a depth camera, a
// laser tracker, a stereo triangulation, a touch probe).
//
// Residual (3):  r = W (x2cam.fromlocal(x2world.tolocal(p_in_world)) − z_in_cam)
//   (units of the points; W = L⁻¹, LLᵀ = Σ in the sensor frame).
// Parameter blocks: x2world (SE3 7), x2cam (SE3 7), and p_in_world (R³) when
// the point is unknown (a landmark, a marker); a known point is a constant.
// The chain is that of the camera factors (pinhole.h): x is the reference
// sensor, x2cam takes it to this sensor.
#pragma once

#include <memory>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/camera/models.h"
#include "boxplus/noise.h"

namespace boxplus {

class PointFunctor {
 public:
  PointFunctor(const Eigen::Vector3d& z, const Eigen::Matrix3d& W,
               const Eigen::Vector3d& p_in_world)
      : z_(z), W_(W), p_(p_in_world) {}

  template <typename T>
  bool Residual(const T* x2world, const T* x2cam, const T* p_in_world, T* r) const {
    T p_in_cam[3];
    camera::ChainToCam(x2world, x2cam, p_in_world, p_in_cam);
    for (int i = 0; i < 3; ++i) r[i] = p_in_cam[i] - T(z_[i]);
    WhitenInPlace<3>(W_, r);
    return true;
  }
  template <typename T>
  bool operator()(const T* x2world, const T* x2cam, T* r) const {
    const T p[3] = {T(p_[0]), T(p_[1]), T(p_[2])};
    return Residual(x2world, x2cam, p, r);
  }
  template <typename T>
  bool operator()(const T* x2world, const T* x2cam, const T* p_in_world, T* r) const {
    return Residual(x2world, x2cam, p_in_world, r);
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Matrix3d W_;
  Eigen::Vector3d p_;
};

// Known point: blocks (x2world, x2cam). Unknown point: (x2world, x2cam, p_in_world).
// `noise` is 3-dim (checked).
std::shared_ptr<ceres::CostFunction> MakePointFactor(const Eigen::Vector3d& z,
                                                     const NoiseModel& noise,
                                                     const Eigen::Vector3d& p_in_world);
std::shared_ptr<ceres::CostFunction> MakeLandmarkPointFactor(const Eigen::Vector3d& z,
                                                             const NoiseModel& noise);

}  // namespace boxplus
