// Depth-to-disparity of a structured-light depth camera (Kinect-style).
//
// Model: the raw disparity d a Kinect reports for a point at depth Z (metres,
// along the IR camera's optical axis) is affine in inverse depth,
//     d = a / Z + b,
// which is the usual Z = 1 / (c₁ d + c₀) with a = 1/c₁, b = −c₀/c₁ (a in
// disparity units · metres, b in disparity units).
// Residual (1):  r = w (a / Z + b − d),  w = 1/σ (a 1-dim NoiseModel, disparity units)
//   Z = [cam_from_rig · world_from_rig⁻¹ · p_in_world]_z   (camera::ChainToCam)
// Parameter blocks: world_from_rig (SE3 7: the reference camera in the board
// frame), cam_from_rig (SE3 7: the reference camera in the IR/depth camera's
// frame), disparity [a, b] (R²). The board point p_in_world is a constant; its
// pixel in the IR image is measured by the board projection factor, so the
// depth of every corner follows from the extrinsics (MTKM paper, Sec. V-B).
#pragma once

#include <memory>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/camera/models.h"
#include "boxplus/noise.h"

namespace boxplus {

class DisparityFunctor {
 public:
  DisparityFunctor(double d, const Eigen::Matrix<double, 1, 1>& W,
                   const Eigen::Vector3d& p_in_world)
      : d_(d), W_(W), p_in_world_(p_in_world) {}

  template <typename T>
  bool operator()(const T* world_from_rig, const T* cam_from_rig, const T* ab, T* r) const {
    const T p[3] = {T(p_in_world_[0]), T(p_in_world_[1]), T(p_in_world_[2])};
    T p_in_cam[3];
    camera::ChainToCam(world_from_rig, cam_from_rig, p, p_in_cam);
    r[0] = ab[0] / p_in_cam[2] + ab[1] - T(d_);
    WhitenInPlace<1>(W_, r);
    return true;
  }

 private:
  double d_;
  Eigen::Matrix<double, 1, 1> W_;
  Eigen::Vector3d p_in_world_;
};

// `noise` of dimension 1 (disparity units). Throws boxplus::Error for another
// noise dimension or non-finite input.
std::shared_ptr<ceres::CostFunction> MakeDisparityFactor(double disparity, const NoiseModel& noise,
                                                         const Eigen::Vector3d& p_in_world);

}  // namespace boxplus
