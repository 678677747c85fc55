#include "boxplus/factors/disparity.h"

#include <cmath>

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeDisparityFactor(double d, double sigma,
                                                         const Eigen::Vector3d& p) {
  BOXPLUS_CHECK(std::isfinite(d) && p.allFinite(), "disparity factor: non-finite input");
  BOXPLUS_CHECK(std::isfinite(sigma) && sigma > 0, "disparity factor: sigma must be > 0, got ",
                sigma);
  return std::make_shared<ceres::AutoDiffCostFunction<DisparityFunctor, 1, 7, 7, 2>>(
      new DisparityFunctor(d, sigma, p));
}

}  // namespace boxplus
