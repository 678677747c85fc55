// Projection of one known 3-D point into a camera of a rig.
//
// Residual (2):  r = W (π(k, p_in_cam) − z),  WᵀW = Σ⁻¹ (pixels; the NoiseModel)
//   p_in_cam = cam_from_rig · world_from_rig⁻¹ · p_in_world   (camera::ChainToCam)
// i.e. world → rig (the reference camera) → cam: the chain of the MTKM paper's
// project_point, so one factor serves mono (cam_from_rig fixed to the
// identity), stereo (cam_from_rig = right_from_left) and hand-eye problems.
// Parameter blocks: intrinsics k (ambient = the camera model's layout, see
// models.h), world_from_rig (SE3, 7), cam_from_rig (SE3, 7). Poses
// [p, q(x,y,z,w)], tangent order [δp, δθ]; z in pixels, p_in_world in the
// world's unit (metres, or the board's).
#pragma once

#include <memory>
#include <string>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/camera/models.h"
#include "boxplus/noise.h"

namespace boxplus {

namespace camera {

// r = W (π(k, p_in_cam) − z) for one point (2 residuals).
template <class Model, typename T>
void ProjectionResidual(const T* k, const T* p_in_cam, const double* z, const Eigen::Matrix2d& W,
                        T* residual) {
  Model::ProjectPoint(k, p_in_cam, residual);
  residual[0] -= T(z[0]);
  residual[1] -= T(z[1]);
  WhitenInPlace<2>(W, residual);
}

}  // namespace camera

template <class Model>
class PointProjectionFunctor {
 public:
  PointProjectionFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
                         const Eigen::Vector3d& p_in_world)
      : z_(z), W_(W), p_in_world_(p_in_world) {}

  template <typename T>
  bool operator()(const T* k, const T* world_from_rig, const T* cam_from_rig, T* residual) const {
    const T p[3] = {T(p_in_world_[0]), T(p_in_world_[1]), T(p_in_world_[2])};
    T p_in_cam[3];
    camera::ChainToCam(world_from_rig, cam_from_rig, p, p_in_cam);
    camera::ProjectionResidual<Model>(k, p_in_cam, z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Eigen::Vector2d& z,
                                                     const Eigen::Matrix2d& W,
                                                     const Eigen::Vector3d& p_in_world) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<PointProjectionFunctor, 2, Model::kSize, 7, 7>>(
        new PointProjectionFunctor(z, W, p_in_world));
  }

 private:
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::Vector3d p_in_world_;
};

// The factor for a camera model chosen at run time by name (see
// camera::WithCameraModel in models.h); `noise` of dimension 2 (pixels).
// Throws boxplus::Error for another name, another noise dimension or
// non-finite input.
std::shared_ptr<ceres::CostFunction> MakePointProjectionFactor(const std::string& model,
                                                               const Eigen::Vector2d& z,
                                                               const NoiseModel& noise,
                                                               const Eigen::Vector3d& p_in_world);

}  // namespace boxplus
