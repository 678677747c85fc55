// The relative-pose costs with hand-written Jacobians (relative_pose.h gives
// the maths). Private to the library: MakeRelativePose2D/3D choose them.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

namespace boxplus::internal {

// g2o convention, SE(2); W the 3×3 whitening.
std::shared_ptr<ceres::CostFunction> MakeRelativePose2DG2oAnalytic(const Eigen::Vector3d& z,
                                                                   const Eigen::Matrix3d& W);
// g2o and log conventions, SE(3); z with a unit quaternion, W the 6×6 whitening.
std::shared_ptr<ceres::CostFunction> MakeRelativePose3DG2oAnalytic(
    const Eigen::Matrix<double, 7, 1>& z, const Eigen::Matrix<double, 6, 6>& W);
std::shared_ptr<ceres::CostFunction> MakeRelativePose3DLogAnalytic(
    const Eigen::Matrix<double, 7, 1>& z, const Eigen::Matrix<double, 6, 6>& W);

}  // namespace boxplus::internal
