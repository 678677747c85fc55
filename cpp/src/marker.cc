#include "boxplus/factors/marker.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeKnownKinematicsMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
    const Eigen::Matrix<double, 7, 1>& hand2base) {
  BOXPLUS_CHECK(z.allFinite() && hand2base.allFinite(), "marker factor: non-finite input");
  return camera::WithCameraModel(model, [&](auto m) {
    return KnownKinematicsMarkerFunctor<decltype(m)>::Create(z, W, hand2base);
  });
}

std::shared_ptr<ceres::CostFunction> MakeDHMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
    const Eigen::VectorXd& joints, const Eigen::Matrix<double, 7, 1>& base2chain,
    const Eigen::Matrix<double, 7, 1>& flange2hand) {
  BOXPLUS_CHECK(joints.size() >= 1, "DH marker factor: no joint readings");
  BOXPLUS_CHECK(joints.allFinite() && z.allFinite() && base2chain.allFinite() &&
                    flange2hand.allFinite(),
                "DH marker factor: non-finite input");
  return camera::WithCameraModel(model, [&](auto m) {
    return DHMarkerFunctor<decltype(m)>::Create(z, W, joints, base2chain, flange2hand);
  });
}

}  // namespace boxplus
