// A point observed from a pose: a landmark seen by a robot (g2o's
// EDGE_SE2_XY, EDGE_SE3_TRACKXYZ with the identity sensor offset), or a 3-D
// point measured by a sensor on a rig (a depth camera, a laser tracker, a
// stereo triangulation, a touch probe).
//
// The error is the point in the observing frame minus its measurement,
//   e = p_in_sensor − z,   p_in_sensor = sensor_from_world · p_in_world,
// with sensor_from_world by where the sensor sits:
//   on the pose x = world_from_sensor itself (SE2 ambient [x, y, θ] or SE3
//     [p, qx, qy, qz, qw], tangent [δp, δθ]):  p_in_sensor = Rᵀ (l − p);
//   on a rig: world_from_rig and cam_from_rig (SE3 7 each), the chain of the
//     camera factors (camera::ChainToCam):
//     p_in_cam = cam_from_rig · world_from_rig⁻¹ · p_in_world.
// Residual r = W e, W the noise's whitening (d × d, in the sensor frame;
// units of the points). Blocks: pose (3 or 7), landmark l (2 or 3) | rig
// (7), cam_from_rig (7) and p_in_world (3) when the point is unknown (a
// landmark, a marker); a known point is a constant. Autodiff (fixed sizes).
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

// p_in_pose = Rᵀ (p_in_world − p) for a pose of dimension D (2: SE2, 3: SE3).
template <int D, typename T>
void PointInPose(const T* world_from_pose, const T* p_in_world, T* p_in_pose) {
  static_assert(D == 2 || D == 3, "poses are SE(2) or SE(3)");
  const T* x = world_from_pose;
  if constexpr (D == 2) {
    using std::cos;
    using std::sin;
    const T c = cos(x[2]), s = sin(x[2]);
    const T dx = p_in_world[0] - x[0], dy = p_in_world[1] - x[1];
    p_in_pose[0] = c * dx + s * dy;
    p_in_pose[1] = -s * dx + c * dy;
  } else {
    T qinv[4], d[3];
    QuatConjugate(x + 3, qinv);
    for (int k = 0; k < 3; ++k) d[k] = p_in_world[k] - x[k];
    QuatRotatePoint(qinv, d, p_in_pose);
  }
}

// e = x⁻¹ · l − z for a pose x of dimension D and a landmark l.
template <int D, typename T>
void ObservedPointError(const T* x, const T* l, const double* z, T* e) {
  PointInPose<D>(x, l, e);
  for (int k = 0; k < D; ++k) e[k] -= z[k];
}

// A landmark seen from a pose: blocks (pose, landmark); `noise` is D-dim
// (checked: boxplus::Error otherwise).
std::shared_ptr<ceres::CostFunction> MakeObservedPoint2D(const Eigen::Vector2d& z,
                                                         const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakeObservedPoint3D(const Eigen::Vector3d& z,
                                                         const NoiseModel& noise);
// A point seen by a sensor on a rig: known point, blocks (world_from_rig,
// cam_from_rig); unknown point, blocks (world_from_rig, cam_from_rig,
// p_in_world). `noise` is 3-dim (checked).
std::shared_ptr<ceres::CostFunction> MakeObservedPointOnRig(const Eigen::Vector3d& z,
                                                            const NoiseModel& noise,
                                                            const Eigen::Vector3d& p_in_world);
std::shared_ptr<ceres::CostFunction> MakeObservedLandmarkOnRig(const Eigen::Vector3d& z,
                                                               const NoiseModel& noise);

}  // namespace boxplus
