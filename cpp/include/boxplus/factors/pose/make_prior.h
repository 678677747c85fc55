// A prior on a variable of any built-in manifold, chosen at run time.
//
// Residual r = W (x ⊟ z), W the noise's whitening (tangent dim × tangent dim).
// Dispatches to the autodiff PriorFunctor of the variable's manifold (Rⁿ, SO2,
// SO3, SE2, SE3, S2). Throws boxplus::Error for other manifolds or sizes that
// do not match.
#pragma once

#include <memory>
#include <string>

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>

#include "boxplus/noise.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakePrior(const ceres::Manifold& manifold,
                                               const Eigen::VectorXd& z_ambient,
                                               const NoiseModel& noise, const std::string& what);

}  // namespace boxplus
