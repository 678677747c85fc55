#include "boxplus/factors/depth/disparity.h"

#include <cmath>

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeDisparityFactor(double disparity, const NoiseModel& noise,
                                                         const Eigen::Vector3d& p_in_world) {
  BOXPLUS_CHECK(std::isfinite(disparity) && p_in_world.allFinite(),
                "disparity factor: non-finite input");
  return std::make_shared<ceres::AutoDiffCostFunction<DisparityFunctor, 1, 7, 7, 2>>(
      new DisparityFunctor(disparity, noise.Fixed<1>("disparity factor"), p_in_world));
}

}  // namespace boxplus
