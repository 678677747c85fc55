#include "boxplus/factors/imu/gravity.h"

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
                                                       const NoiseModel& noise,
                                                       const Eigen::Vector3d& g_in_world) {
  BOXPLUS_CHECK(z.allFinite() && g_in_world.allFinite(), "gravity factor: non-finite input");
  const Eigen::Matrix3d W = noise.Fixed<3>("gravity factor");
  switch (GravityModelSize(model)) {
    case 0:
      return GravityFunctor<0>::Create(z, W, g_in_world);
    case 1:
      return GravityFunctor<1>::Create(z, W, g_in_world);
    default:
      return GravityFunctor<4>::Create(z, W, g_in_world);
  }
}

}  // namespace boxplus
