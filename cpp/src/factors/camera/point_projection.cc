#include "boxplus/factors/camera/point_projection.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakePointProjectionFactor(const std::string& model,
                                                               const Eigen::Vector2d& z,
                                                               const NoiseModel& noise,
                                                               const Eigen::Vector3d& p_in_world) {
  BOXPLUS_CHECK(z.allFinite() && p_in_world.allFinite(), "projection factor: non-finite input");
  const Eigen::Matrix2d W = noise.Fixed<2>("projection factor");
  return camera::WithCameraModel(
      model, [&](auto m) { return PointProjectionFunctor<decltype(m)>::Create(z, W, p_in_world); });
}

}  // namespace boxplus
