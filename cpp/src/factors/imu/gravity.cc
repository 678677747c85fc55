#include "boxplus/factors/imu/gravity.h"

#include "boxplus/errors.h"

namespace boxplus {

int GravityModelSize(const std::string& model) {
  if (model == "rotation") return 0;
  if (model == "scale") return 1;
  if (model == "scale_bias") return 4;
  if (model == "axis_scale_bias") return 6;
  if (model == "axis_scale_bias_misalignment") return 9;
  throw Error("unknown gravity model '" + model +
              "' (expected rotation, scale, scale_bias, axis_scale_bias or "
              "axis_scale_bias_misalignment)");
}

namespace {

template <int kImu>
std::shared_ptr<ceres::CostFunction> Make(int accel_size, const Eigen::Vector3d& z,
                                          const Eigen::Matrix3d& W,
                                          const Eigen::Vector3d& g_in_world) {
  switch (accel_size) {
    case 0:
      return GravityFunctor<0, kImu>::Create(z, W, g_in_world);
    case 1:
      return GravityFunctor<1, kImu>::Create(z, W, g_in_world);
    case 4:
      return GravityFunctor<4, kImu>::Create(z, W, g_in_world);
    case 6:
      return GravityFunctor<6, kImu>::Create(z, W, g_in_world);
    default:
      return GravityFunctor<9, kImu>::Create(z, W, g_in_world);
  }
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeGravityFactor(const std::string& model,
                                                       const Eigen::Vector3d& z,
                                                       const NoiseModel& noise,
                                                       const Eigen::Vector3d& g_in_world,
                                                       int imu_size) {
  BOXPLUS_CHECK(z.allFinite() && g_in_world.allFinite(), "gravity factor: non-finite input");
  BOXPLUS_CHECK(imu_size == 4 || imu_size == 7, "gravity factor: imu_from_rig must be an SO3 (4) ",
                "or SE3 (7) block, got ", imu_size, " numbers");
  const Eigen::Matrix3d W = noise.Fixed<3>("gravity factor");
  const int n = GravityModelSize(model);
  return imu_size == 4 ? Make<4>(n, z, W, g_in_world) : Make<7>(n, z, W, g_in_world);
}

}  // namespace boxplus
