#include "boxplus/factors/pose/relative_pose.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeRelativePoseFactor(const Eigen::Matrix<double, 7, 1>& z,
                                                            const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose factor: non-finite z");
  return std::make_shared<ceres::AutoDiffCostFunction<RelativePoseFunctor, 6, 7, 7>>(
      new RelativePoseFunctor(z, noise.Fixed<6>("relative pose factor")));
}

}  // namespace boxplus
