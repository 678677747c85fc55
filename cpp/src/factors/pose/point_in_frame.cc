#include "boxplus/factors/pose/point_in_frame.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/errors.h"

namespace boxplus {
namespace {

template <int D>
struct PointInPoseFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    PointInPoseError<D>(x, l, offset.data(), z.data(), r);
    WhitenInPlace<D>(W, r);
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D == 2 ? 3 : 7, 1> offset;
  Eigen::Matrix<double, D, D> W;
};

template <int D>
struct PointDifferenceFunctor {
  template <typename T>
  bool operator()(const T* p, const T* l, T* r) const {
    PointDifferenceError<D>(p, l, z.data(), r);
    WhitenInPlace<D>(W, r);
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D, D> W;
};

template <int D>
struct PositionPriorFunctor {
  template <typename T>
  bool operator()(const T* t, T* r) const {
    PositionPriorError<D>(t, z.data(), r);
    WhitenInPlace<D>(W, r);
    return true;
  }
  Eigen::Matrix<double, D, 1> z;
  Eigen::Matrix<double, D, D> W;
};

struct BearingFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    Bearing2DError(x, l, &z, r);
    r[0] *= W;
    return true;
  }
  double z;
  double W;
};

template <int D, int B>
std::shared_ptr<ceres::CostFunction> PositionPrior(const Eigen::VectorXd& z,
                                                   const NoiseModel& noise) {
  return std::make_shared<ceres::AutoDiffCostFunction<PositionPriorFunctor<D>, D, B>>(
      new PositionPriorFunctor<D>{z, noise.Fixed<D>("position prior")});
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakePointInPose2D(const Eigen::Vector2d& z,
                                                       const Eigen::Vector3d& offset,
                                                       const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite() && offset.allFinite(),
                "point in pose 2D: measurement and offset must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<PointInPoseFunctor<2>, 2, 3, 2>>(
      new PointInPoseFunctor<2>{z, offset, noise.Fixed<2>("point in pose 2D")});
}

std::shared_ptr<ceres::CostFunction> MakePointInPose3D(const Eigen::Vector3d& z,
                                                       const Eigen::Matrix<double, 7, 1>& offset,
                                                       const NoiseModel& noise) {
  BOXPLUS_CHECK(
      z.allFinite() && offset.allFinite() && std::abs(offset.tail<4>().norm() - 1.0) < 1e-9,
      "point in pose 3D: measurement and offset must be finite, the offset's "
      "quaternion unit");
  return std::make_shared<ceres::AutoDiffCostFunction<PointInPoseFunctor<3>, 3, 7, 3>>(
      new PointInPoseFunctor<3>{z, offset, noise.Fixed<3>("point in pose 3D")});
}

std::shared_ptr<ceres::CostFunction> MakePointDifference(const Eigen::VectorXd& z,
                                                         const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "point difference: measurement must be finite");
  if (z.size() == 2) {
    return std::make_shared<ceres::AutoDiffCostFunction<PointDifferenceFunctor<2>, 2, 2, 2>>(
        new PointDifferenceFunctor<2>{z, noise.Fixed<2>("point difference")});
  }
  BOXPLUS_CHECK(z.size() == 3, "point difference: measurement of 2 or 3 numbers, got ", z.size());
  return std::make_shared<ceres::AutoDiffCostFunction<PointDifferenceFunctor<3>, 3, 3, 3>>(
      new PointDifferenceFunctor<3>{z, noise.Fixed<3>("point difference")});
}

std::shared_ptr<ceres::CostFunction> MakePositionPrior(const Eigen::VectorXd& z, int block_size,
                                                       const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite(), "position prior: measurement must be finite");
  if (z.size() == 2 && block_size == 2) return PositionPrior<2, 2>(z, noise);
  if (z.size() == 2 && block_size == 3) return PositionPrior<2, 3>(z, noise);
  if (z.size() == 3 && block_size == 3) return PositionPrior<3, 3>(z, noise);
  if (z.size() == 3 && block_size == 7) return PositionPrior<3, 7>(z, noise);
  throw Error("position prior: a measurement of " + std::to_string(z.size()) +
              " numbers on a block of " + std::to_string(block_size));
}

std::shared_ptr<ceres::CostFunction> MakeBearing2D(double z, const NoiseModel& noise) {
  BOXPLUS_CHECK(std::isfinite(z), "bearing: measurement must be finite");
  return std::make_shared<ceres::AutoDiffCostFunction<BearingFunctor, 1, 3, 2>>(
      new BearingFunctor{z, noise.Fixed<1>("bearing")(0, 0)});
}

}  // namespace boxplus
