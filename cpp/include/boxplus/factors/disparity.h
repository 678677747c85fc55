// Depth-to-disparity of a structured-light depth camera (Kinect-style).
//
// Model: the raw disparity d a Kinect reports for a point at depth Z (metres,
// along the IR camera's optical axis) is affine in inverse depth,
//     d = a / Z + b,
// which is the usual Z = 1 / (c₁ d + c₀) with a = 1/c₁, b = −c₀/c₁ (a in
// disparity units · metres, b in disparity units).
// Residual (1):  r = (a / Z + b − d) / σ,
//   Z = [x2cam.fromlocal(x2world.tolocal(p_in_world))]_z
// Parameter blocks: x2world (SE3 7: reference camera → board), x2cam (SE3 7:
// reference camera → the IR/depth camera), disparity [a, b] (R²). The board
// point p_in_world is a constant; its pixel in the IR image is measured by the
// board projection factor, so the depth of every corner follows from the
// extrinsics (MTKM paper, Sec. V-B).
#pragma once

#include <memory>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/pinhole.h"

namespace boxplus {

class DisparityFunctor {
 public:
  DisparityFunctor(double d, double sigma, const Eigen::Vector3d& p_in_world)
      : d_(d), w_(1.0 / sigma), p_(p_in_world) {}

  template <typename T>
  bool operator()(const T* x2world, const T* x2cam, const T* ab, T* r) const {
    const T p[3] = {T(p_[0]), T(p_[1]), T(p_[2])};
    T p_in_cam[3];
    camera::ChainToCam(x2world, x2cam, p, p_in_cam);
    r[0] = T(w_) * (ab[0] / p_in_cam[2] + ab[1] - T(d_));
    return true;
  }

 private:
  double d_, w_;
  Eigen::Vector3d p_;
};

// Throws boxplus::Error unless sigma > 0 and the inputs are finite.
std::shared_ptr<ceres::CostFunction> MakeDisparityFactor(double disparity, double sigma,
                                                         const Eigen::Vector3d& p_in_world);

}  // namespace boxplus
