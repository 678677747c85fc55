#include "boxplus/factors/pose/chordal_relative_pose.h"

#include <ceres/autodiff_cost_function.h>

#include <cmath>

#include <Eigen/LU>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "boxplus/noise.h"

namespace boxplus {
namespace {

struct Chordal2DFunctor {
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    ChordalRelativePose2DResidual(xi, xj, z.data(), p, r);
    return true;
  }
  Eigen::Vector3d z;
  ChordalPrecisions p;
};

struct Chordal3DFunctor {
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    ChordalRelativePose3DResidual(xi, xj, z.data(), p, r);
    return true;
  }
  Eigen::Matrix<double, 7, 1> z;
  ChordalPrecisions p;
};

}  // namespace

ChordalPrecisions ChordalPrecisionsOf(const NoiseModel& noise) {
  const int n = noise.dim();
  BOXPLUS_CHECK(n == 3 || n == 6, "chordal precisions: noise must be of dimension 3 or 6, got ", n);
  const Eigen::MatrixXd information = noise.information();
  const int d = n == 3 ? 2 : 3;
  const Eigen::MatrixXd Ot = information.topLeftCorner(d, d);
  ChordalPrecisions p;
  p.tau = d / Ot.inverse().trace();
  if (d == 2) {
    p.kappa = information(2, 2);
  } else {
    const Eigen::Matrix3d OR = information.bottomRightCorner<3, 3>();
    p.kappa = 3.0 / (2.0 * OR.inverse().trace());
  }
  return p;
}

NoiseModel ChordalNoise(const NoiseModel& noise) {
  const ChordalPrecisions p = ChordalPrecisionsOf(noise);
  const int d = noise.dim() == 3 ? 2 : 3;
  // The same √τ, √κ as the residual templates multiply by: r = W e exactly.
  Eigen::VectorXd w(d + d * d);
  w.head(d).setConstant(std::sqrt(p.tau));
  w.tail(d * d).setConstant(std::sqrt(p.kappa));
  return NoiseModel::DiagonalSqrtInformation(w, "chordal noise");
}

std::shared_ptr<ceres::CostFunction> MakeChordalRelativePose2D(const Eigen::Vector3d& z,
                                                               const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 2D (SE-Sync): measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<Chordal2DFunctor, 6, 3, 3>>(
      new Chordal2DFunctor{z, ChordalPrecisionsOf(noise)});
}

std::shared_ptr<ceres::CostFunction> MakeChordalRelativePose3D(const Eigen::Matrix<double, 7, 1>& z,
                                                               const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 3D (SE-Sync): measurement must be finite");
  Eigen::Matrix<double, 7, 1> zn = z;
  BOXPLUS_CHECK(NormalizeQuaternion(z.data() + 3, zn.data() + 3),
                "relative pose 3D (SE-Sync): measured quaternion has zero norm");
  return std::make_shared<ceres::AutoDiffCostFunction<Chordal3DFunctor, 12, 7, 7>>(
      new Chordal3DFunctor{zn, ChordalPrecisionsOf(noise)});
}

}  // namespace boxplus
