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
  return ChordalPrecisionsOfInformation(noise.information());
}

ChordalPrecisions ChordalPrecisionsOfInformation(const Eigen::MatrixXd& information) {
  const int n = static_cast<int>(information.rows());
  BOXPLUS_CHECK((n == 3 || n == 6) && information.cols() == n,
                "chordal precisions: information must be 3 x 3 or 6 x 6, got ", information.rows(),
                " x ", information.cols());
  ChordalPrecisions p;
  // Fixed-size inverses (closed forms): what the chordal initialisation's
  // messages about weights that underflow or overflow were written against.
  if (n == 3) {
    const Eigen::Matrix2d Ot = information.topLeftCorner<2, 2>();
    p.tau = 2.0 / Ot.inverse().trace();
    p.kappa = information(2, 2);
  } else {
    const Eigen::Matrix3d Ot = information.topLeftCorner<3, 3>();
    const Eigen::Matrix3d OR = information.bottomRightCorner<3, 3>();
    p.tau = 3.0 / Ot.inverse().trace();
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
