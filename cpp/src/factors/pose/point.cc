#include "boxplus/factors/pose/point.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakePointFactor(const Eigen::Vector3d& z,
                                                     const Eigen::Matrix3d& W,
                                                     const Eigen::Vector3d& p) {
  BOXPLUS_CHECK(z.allFinite() && p.allFinite(), "point factor: non-finite input");
  return std::make_shared<ceres::AutoDiffCostFunction<PointFunctor, 3, 7, 7>>(
      new PointFunctor(z, W, p));
}

std::shared_ptr<ceres::CostFunction> MakeLandmarkPointFactor(const Eigen::Vector3d& z,
                                                             const Eigen::Matrix3d& W) {
  BOXPLUS_CHECK(z.allFinite(), "point factor: non-finite z");
  return std::make_shared<ceres::AutoDiffCostFunction<PointFunctor, 3, 7, 7, 3>>(
      new PointFunctor(z, W, Eigen::Vector3d::Zero()));
}

}  // namespace boxplus
