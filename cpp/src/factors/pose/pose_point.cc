#include "boxplus/factors/pose/pose_point.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/noise.h"

namespace boxplus {
namespace {

template <int D>
struct PosePointFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    Eigen::Matrix<T, D, 1> e;
    if constexpr (D == 2) {
      PosePoint2DError(x, l, z.data(), e.data());
    } else {
      PosePoint3DError(x, l, z.data(), e.data());
    }
    Eigen::Map<Eigen::Matrix<T, D, 1>> r_map(r);
    r_map = U.template cast<T>() * e;
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D, D> U;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakePosePoint2D(const Eigen::Vector2d& z,
                                                     const Eigen::Matrix2d& information) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 2D: measurement must be finite");
  const Eigen::Matrix2d U = NoiseModel::Information(information, "pose-point 2D").sqrt_information();
  return std::make_shared<ceres::AutoDiffCostFunction<PosePointFunctor<2>, 2, 3, 2>>(
      new PosePointFunctor<2>{z, U});
}

std::shared_ptr<ceres::CostFunction> MakePosePoint3D(const Eigen::Vector3d& z,
                                                     const Eigen::Matrix3d& information) {
  BOXPLUS_CHECK(z.allFinite(), "pose-point 3D: measurement must be finite");
  const Eigen::Matrix3d U = NoiseModel::Information(information, "pose-point 3D").sqrt_information();
  return std::make_shared<ceres::AutoDiffCostFunction<PosePointFunctor<3>, 3, 7, 3>>(
      new PosePointFunctor<3>{z, U});
}

}  // namespace boxplus
