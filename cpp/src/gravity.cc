#include "boxplus/factors/gravity.h"

#include "boxplus/errors.h"

namespace boxplus {

int GravityModelSize(const std::string& model) {
  if (model == "rotation") return 0;
  if (model == "scale") return 1;
  if (model == "scale_bias") return 4;
  throw Error("unknown gravity model '" + model + "' (expected rotation, scale or scale_bias)");
}

std::shared_ptr<ceres::CostFunction> MakeGravityFactor(const std::string& model,
                                                       const Eigen::Vector3d& z,
                                                       const Eigen::Matrix3d& W,
                                                       const Eigen::Vector3d& g) {
  BOXPLUS_CHECK(z.allFinite() && g.allFinite(), "gravity factor: non-finite input");
  switch (GravityModelSize(model)) {
    case 0:
      return GravityFunctor<0>::Create(z, W, g);
    case 1:
      return GravityFunctor<1>::Create(z, W, g);
    default:
      return GravityFunctor<4>::Create(z, W, g);
  }
}

}  // namespace boxplus
