#include "boxplus/factors/pinhole.h"

#include "boxplus/errors.h"

namespace boxplus {

namespace {
template <class Model>
bool Is(const std::string& name) {
  return name == Model::kName;
}
}  // namespace

int CameraModelSize(const std::string& model) {
  if (Is<camera::SimpleRadial>(model)) return camera::SimpleRadial::kSize;
  if (Is<camera::Pinhole>(model)) return camera::Pinhole::kSize;
  if (Is<camera::Radial2>(model)) return camera::Radial2::kSize;
  if (Is<camera::OpenCV5>(model)) return camera::OpenCV5::kSize;
  throw Error("unknown camera model '" + model +
              "' (expected simple_radial, pinhole, radial2 or opencv5)");
}

std::shared_ptr<ceres::CostFunction> MakePinholePointFactor(const std::string& model,
                                                            const Eigen::Vector2d& z,
                                                            const Eigen::Matrix2d& W,
                                                            const Eigen::Vector3d& p) {
  CameraModelSize(model);  // validates the name
  if (Is<camera::SimpleRadial>(model)) return PinholePointFunctor<camera::SimpleRadial>::Create(z, W, p);
  if (Is<camera::Pinhole>(model)) return PinholePointFunctor<camera::Pinhole>::Create(z, W, p);
  if (Is<camera::Radial2>(model)) return PinholePointFunctor<camera::Radial2>::Create(z, W, p);
  return PinholePointFunctor<camera::OpenCV5>::Create(z, W, p);
}

}  // namespace boxplus
