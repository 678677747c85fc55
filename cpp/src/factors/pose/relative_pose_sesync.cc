#include "boxplus/factors/pose/relative_pose_sesync.h"

#include <ceres/autodiff_cost_function.h>

#include <Eigen/LU>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "boxplus/noise.h"

namespace boxplus {
namespace {

struct SESync2DFunctor {
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    RelativePose2DSESyncResidual(xi, xj, z.data(), p, r);
    return true;
  }
  Eigen::Vector3d z;
  SESyncPrecisions p;
};

struct SESync3DFunctor {
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    RelativePose3DSESyncResidual(xi, xj, z.data(), p, r);
    return true;
  }
  Eigen::Matrix<double, 7, 1> z;
  SESyncPrecisions p;
};

}  // namespace

SESyncPrecisions SESyncPrecisionsOf(const NoiseModel& noise) {
  const int n = noise.dim();
  BOXPLUS_CHECK(n == 3 || n == 6, "SE-Sync precisions: noise must be of dimension 3 or 6, got ", n);
  const Eigen::MatrixXd information = noise.information();
  const int d = n == 3 ? 2 : 3;
  const Eigen::MatrixXd Ot = information.topLeftCorner(d, d);
  SESyncPrecisions p;
  p.tau = d / Ot.inverse().trace();
  if (d == 2) {
    p.kappa = information(2, 2);
  } else {
    const Eigen::Matrix3d OR = information.bottomRightCorner<3, 3>();
    p.kappa = 3.0 / (2.0 * OR.inverse().trace());
  }
  return p;
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose2DSESync(const Eigen::Vector3d& z,
                                                              const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 2D (SE-Sync): measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<SESync2DFunctor, 6, 3, 3>>(
      new SESync2DFunctor{z, SESyncPrecisionsOf(noise)});
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose3DSESync(const Eigen::Matrix<double, 7, 1>& z,
                                                              const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 3D (SE-Sync): measurement must be finite");
  Eigen::Matrix<double, 7, 1> zn = z;
  BOXPLUS_CHECK(NormalizeQuaternion(z.data() + 3, zn.data() + 3),
                "relative pose 3D (SE-Sync): measured quaternion has zero norm");
  return std::make_shared<ceres::AutoDiffCostFunction<SESync3DFunctor, 12, 7, 7>>(
      new SESync3DFunctor{zn, SESyncPrecisionsOf(noise)});
}

}  // namespace boxplus
