// Landmark position observed from a pose (2D: g2o's EDGE_SE2_XY, 3D:
// EDGE_SE3_TRACKXYZ with the identity sensor offset).
//
// Pose x = (p, R), ambient SE2 [x, y, θ] or SE3 [p, qx, qy, qz, qw], tangent
// [δp, δθ]; landmark l ∈ Rᵈ in the parent (world) frame; measurement z ∈ Rᵈ,
// the landmark in the pose's frame. Error
//   e = x⁻¹ · l − z = Rᵀ (l − p) − z
// residual r = W e, W the noise's whitening (d×d). Blocks: pose (3 or 7), landmark (d).
// Autodiff (fixed sizes).
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

template <typename T>
void PosePoint2DError(const T* x, const T* l, const double* z, T* e) {
  using std::cos;
  using std::sin;
  const T c = cos(x[2]), s = sin(x[2]);
  const T dx = l[0] - x[0], dy = l[1] - x[1];
  e[0] = c * dx + s * dy - z[0];
  e[1] = -s * dx + c * dy - z[1];
}

template <typename T>
void PosePoint3DError(const T* x, const T* l, const double* z, T* e) {
  T qinv[4], d[3];
  QuatConjugate(x + 3, qinv);
  for (int k = 0; k < 3; ++k) d[k] = l[k] - x[k];
  QuatRotatePoint(qinv, d, e);
  for (int k = 0; k < 3; ++k) e[k] -= z[k];
}

std::shared_ptr<ceres::CostFunction> MakePosePoint2D(const Eigen::Vector2d& z,
                                                     const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakePosePoint3D(const Eigen::Vector3d& z,
                                                     const NoiseModel& noise);

}  // namespace boxplus
