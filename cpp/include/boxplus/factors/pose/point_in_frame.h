// A point measured in a frame: g2o's point edges beyond EDGE_SE2_XY /
// EDGE_SE3_TRACKXYZ with the identity offset (those are observed_point.h).
//
// Pose x: SE2 ambient [x, y, θ] / SE3 [p, qx, qy, qz, qw], tangent [δp, δθ];
// points l, p ∈ Rᵈ in the world frame; offset o = x_from_sensor (the
// PARAMS_SE2OFFSET [x, y, θ] / PARAMS_SE3OFFSET [t, qxyzw] line). As g2o's
// computeError:
//   point in a sensor on a pose  e = (x · o)⁻¹ · l − z   EDGE_SE2_POINTXY_OFFSET
//                                                        (EdgeSE2PointXYOffset),
//                                                        EDGE_SE3_TRACKXYZ with a
//                                                        non-identity offset
//                                                        (EdgeSE3PointXYZ)
//   point from a point           e = (l − p) − z         EDGE_POINTXY, EDGE_POINTXYZ
//   position prior               e = t − z               EDGE_PRIOR_XY, EDGE_POINTXYZ_PRIOR
//                                                        (t = l), EDGE_PRIOR_SE2_XY,
//                                                        EDGE_SE3_XYZ_PRIOR (t = the
//                                                        pose's translation; g2o's
//                                                        EdgeSE3XYZPrior ignores its
//                                                        offset in computeError)
//   bearing only (2D)            e = wrap(atan2(d_y, d_x) − z), d = x⁻¹ · l
//                                                        EDGE_BEARING_SE2_XY
//                                                        (EdgeSE2PointXYBearing)
// Residual r = W e (W the whitening of the file's information, d×d or 1×1).
// Autodiff; blocks in the order of the edge's ids.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/pose/offset_pose.h"
#include "boxplus/manifolds/rotation_math.h"
#include "boxplus/noise.h"

namespace boxplus {

template <int D, typename T>
void PointInPoseError(const T* x, const T* l, const double* offset, const double* z, T* e) {
  constexpr int N = D == 2 ? 3 : 7;
  T s[N], s_inv[N];
  ComposePose<D, T>(x, offset, s);
  InversePose<D>(s, s_inv);
  if constexpr (D == 2) {
    using std::cos;
    using std::sin;
    const T c = cos(s_inv[2]), sn = sin(s_inv[2]);
    e[0] = s_inv[0] + c * l[0] - sn * l[1] - z[0];
    e[1] = s_inv[1] + sn * l[0] + c * l[1] - z[1];
  } else {
    T rl[3];
    QuatRotatePoint(s_inv + 3, l, rl);
    for (int k = 0; k < 3; ++k) e[k] = s_inv[k] + rl[k] - z[k];
  }
}

template <int D, typename T>
void PointDifferenceError(const T* p, const T* l, const double* z, T* e) {
  for (int k = 0; k < D; ++k) e[k] = (l[k] - p[k]) - z[k];
}

// t: the first D ambient entries of a point or a pose (its translation).
template <int D, typename T>
void PositionPriorError(const T* t, const double* z, T* e) {
  for (int k = 0; k < D; ++k) e[k] = t[k] - z[k];
}

template <typename T>
void Bearing2DError(const T* x, const T* l, const double* z, T* e) {
  using std::atan2;
  using std::cos;
  using std::sin;
  const T c = cos(x[2]), s = sin(x[2]);
  const T dx = l[0] - x[0], dy = l[1] - x[1];
  e[0] = WrapAngle(atan2(-s * dx + c * dy, c * dx + s * dy) - z[0]);
}

// Blocks: pose (3 / 7), point (2 / 3).
std::shared_ptr<ceres::CostFunction> MakePointInPose2D(const Eigen::Vector2d& z,
                                                       const Eigen::Vector3d& offset,
                                                       const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakePointInPose3D(const Eigen::Vector3d& z,
                                                       const Eigen::Matrix<double, 7, 1>& offset,
                                                       const NoiseModel& noise);
// Blocks: p, l (both Rᵈ, d = z.size(), 2 or 3).
std::shared_ptr<ceres::CostFunction> MakePointDifference(const Eigen::VectorXd& z,
                                                         const NoiseModel& noise);
// One block of `block_size` ambient numbers whose first d = z.size() are the
// position: a point (block_size = d) or a pose (3 for SE2, 7 for SE3).
std::shared_ptr<ceres::CostFunction> MakePositionPrior(const Eigen::VectorXd& z, int block_size,
                                                       const NoiseModel& noise);
// Blocks: pose (SE2, 3), point (2). z: the bearing in radians.
std::shared_ptr<ceres::CostFunction> MakeBearing2D(double z, const NoiseModel& noise);

}  // namespace boxplus
