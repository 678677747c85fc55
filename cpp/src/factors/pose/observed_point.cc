#include "boxplus/factors/pose/observed_point.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/errors.h"
#include "boxplus/factors/camera/models.h"

namespace boxplus {
namespace {

template <int D>
struct FromPoseFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    ObservedPointError<D>(x, l, z.data(), r);
    WhitenInPlace<D>(W, r);
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D, D> W;
};

// The rig's point is a block (a landmark) or the constant p_in_world.
struct OnRigFunctor {
  template <typename T>
  bool Residual(const T* world_from_rig, const T* cam_from_rig, const T* p_in_world, T* r) const {
    camera::ChainToCam(world_from_rig, cam_from_rig, p_in_world, r);
    for (int i = 0; i < 3; ++i) r[i] -= T(z[i]);
    WhitenInPlace<3>(W, r);
    return true;
  }
  template <typename T>
  bool operator()(const T* world_from_rig, const T* cam_from_rig, T* r) const {
    const T p[3] = {T(p_in_world[0]), T(p_in_world[1]), T(p_in_world[2])};
    return Residual(world_from_rig, cam_from_rig, p, r);
  }
  template <typename T>
  bool operator()(const T* world_from_rig, const T* cam_from_rig, const T* p, T* r) const {
    return Residual(world_from_rig, cam_from_rig, p, r);
  }
  Eigen::Vector3d z;
  Eigen::Matrix3d W;
  Eigen::Vector3d p_in_world;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeObservedPoint2D(const Eigen::Vector2d& z,
                                                         const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 2D: measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<FromPoseFunctor<2>, 2, 3, 2>>(
      new FromPoseFunctor<2>{z, noise.Fixed<2>("pose-point 2D")});
}

std::shared_ptr<ceres::CostFunction> MakeObservedPoint3D(const Eigen::Vector3d& z,
                                                         const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 3D: measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<FromPoseFunctor<3>, 3, 7, 3>>(
      new FromPoseFunctor<3>{z, noise.Fixed<3>("pose-point 3D")});
}

std::shared_ptr<ceres::CostFunction> MakeObservedPointOnRig(const Eigen::Vector3d& z,
                                                            const NoiseModel& noise,
                                                            const Eigen::Vector3d& p_in_world) {
  BOXPLUS_CHECK(z.allFinite() && p_in_world.allFinite(), "point factor: non-finite input");
  return std::make_shared<ceres::AutoDiffCostFunction<OnRigFunctor, 3, 7, 7>>(
      new OnRigFunctor{z, noise.Fixed<3>("point factor"), p_in_world});
}

std::shared_ptr<ceres::CostFunction> MakeObservedLandmarkOnRig(const Eigen::Vector3d& z,
                                                               const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "point factor: non-finite z");
  return std::make_shared<ceres::AutoDiffCostFunction<OnRigFunctor, 3, 7, 7, 3>>(
      new OnRigFunctor{z, noise.Fixed<3>("point factor"), Eigen::Vector3d::Zero()});
}

}  // namespace boxplus
