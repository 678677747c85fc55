#include "boxplus/factors/kinematics/marker.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeKnownKinematicsMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const NoiseModel& noise,
    const Eigen::Matrix<double, 7, 1>& base_from_hand) {
  BOXPLUS_CHECK(z.allFinite() && base_from_hand.allFinite(), "marker factor: non-finite input");
  const Eigen::Matrix2d W = noise.Fixed<2>("marker factor");
  return camera::WithCameraModel(model, [&](auto m) {
    return KnownKinematicsMarkerFunctor<decltype(m)>::Create(z, W, base_from_hand);
  });
}

std::shared_ptr<ceres::CostFunction> MakeDHMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const NoiseModel& noise,
    const Eigen::VectorXd& joints, const Eigen::Matrix<double, 7, 1>& base_from_chain,
    const Eigen::Matrix<double, 7, 1>& flange_from_hand) {
  BOXPLUS_CHECK(joints.size() >= 1, "DH marker factor: no joint readings");
  BOXPLUS_CHECK(joints.allFinite() && z.allFinite() && base_from_chain.allFinite() &&
                    flange_from_hand.allFinite(),
                "DH marker factor: non-finite input");
  const Eigen::Matrix2d W = noise.Fixed<2>("DH marker factor");
  return camera::WithCameraModel(model, [&](auto m) {
    return DHMarkerFunctor<decltype(m)>::Create(z, W, joints, base_from_chain, flange_from_hand);
  });
}

}  // namespace boxplus
