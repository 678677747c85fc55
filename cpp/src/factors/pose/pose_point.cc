#include "boxplus/factors/pose/pose_point.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/noise.h"

namespace boxplus {
namespace {

template <int D>
struct PosePointFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    if constexpr (D == 2) {
      PosePoint2DError(x, l, z.data(), r);
    } else {
      PosePoint3DError(x, l, z.data(), r);
    }
    WhitenInPlace<D>(U, r);
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D, D> U;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakePosePoint2D(const Eigen::Vector2d& z,
                                                     const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 2D: measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<PosePointFunctor<2>, 2, 3, 2>>(
      new PosePointFunctor<2>{z, noise.Fixed<2>("pose-point 2D")});
}

std::shared_ptr<ceres::CostFunction> MakePosePoint3D(const Eigen::Vector3d& z,
                                                     const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 3D: measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<PosePointFunctor<3>, 3, 7, 3>>(
      new PosePointFunctor<3>{z, noise.Fixed<3>("pose-point 3D")});
}

}  // namespace boxplus
