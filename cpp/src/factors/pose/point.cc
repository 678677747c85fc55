#include "boxplus/factors/pose/point.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakePointFactor(const Eigen::Vector3d& z,
                                                     const NoiseModel& noise,
                                                     const Eigen::Vector3d& p) {
  BOXPLUS_CHECK(z.allFinite() && p.allFinite(), "point factor: non-finite input");
  return std::make_shared<ceres::AutoDiffCostFunction<PointFunctor, 3, 7, 7>>(
      new PointFunctor(z, noise.Fixed<3>("point factor"), p));
}

std::shared_ptr<ceres::CostFunction> MakeLandmarkPointFactor(const Eigen::Vector3d& z,
                                                             const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "point factor: non-finite z");
  return std::make_shared<ceres::AutoDiffCostFunction<PointFunctor, 3, 7, 7, 3>>(
      new PointFunctor(z, noise.Fixed<3>("point factor"), Eigen::Vector3d::Zero()));
}

}  // namespace boxplus
