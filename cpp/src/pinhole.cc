#include "boxplus/factors/pinhole.h"

#include "boxplus/errors.h"

namespace boxplus {

namespace camera {
void ThrowUnknownCameraModel(const std::string& name) {
  throw Error("unknown camera model '" + name +
              "' (expected simple_radial, pinhole, radial1, radial2 or opencv5)");
}
}  // namespace camera

int CameraModelSize(const std::string& model) {
  return camera::WithCameraModel(model, [](auto m) { return decltype(m)::kSize; });
}

std::shared_ptr<ceres::CostFunction> MakePinholePointFactor(const std::string& model,
                                                            const Eigen::Vector2d& z,
                                                            const Eigen::Matrix2d& W,
                                                            const Eigen::Vector3d& p) {
  return camera::WithCameraModel(model, [&](auto m) {
    return PinholePointFunctor<decltype(m)>::Create(z, W, p);
  });
}

}  // namespace boxplus
