// 2D bearing–range observation of a landmark from a pose (Victoria Park
// style laser/feature data).
//
// Pose x = (p, θ), ambient/tangent [x, y, θ]; landmark l ∈ R² in the world
// frame; measurement z = [bearing (rad, counter-clockwise from the pose's x
// axis), range (m)]. With v = R(θ)ᵀ (l − p), the landmark in the pose frame,
//   e = [wrap(atan2(v_y, v_x) − z_b),  ‖v‖ − z_r]
// residual r = W e, W the noise's whitening (2×2, order [bearing, range]). Blocks: pose (3),
// landmark (2). Undefined when the landmark sits on the pose (‖v‖ = 0):
// Evaluate then returns false and the solver rejects the step.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

template <typename T>
bool BearingRange2DError(const T* x, const T* l, const double* z, T* e) {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T c = cos(x[2]), s = sin(x[2]);
  const T dx = l[0] - x[0], dy = l[1] - x[1];
  const T vx = c * dx + s * dy, vy = -s * dx + c * dy;
  const T r2 = vx * vx + vy * vy;
  if (!(r2 > T(0.0))) return false;
  e[0] = WrapAngle(T(atan2(vy, vx) - z[0]));
  e[1] = sqrt(r2) - z[1];
  return true;
}

std::shared_ptr<ceres::CostFunction> MakeBearingRange2D(const Eigen::Vector2d& z,
                                                        const NoiseModel& noise);

}  // namespace boxplus
