#include "boxplus/factors/pose/offset_pose.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/errors.h"

namespace boxplus {
namespace {

constexpr int Ambient(int d) { return d == 2 ? 3 : 7; }
constexpr int ErrorDim(int d) { return d == 2 ? 3 : 6; }

template <int D>
struct OffsetPoseFunctor {
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    OffsetPoseError<D>(a, b, offset_a.data(), offset_b.data(), z.data(), r);
    WhitenInPlace<ErrorDim(D)>(W, r);
    return true;
  }
  Eigen::Matrix<double, Ambient(D), 1> z, offset_a, offset_b;
  Eigen::Matrix<double, ErrorDim(D), ErrorDim(D)> W;
};

template <int D>
struct OffsetPosePriorFunctor {
  template <typename T>
  bool operator()(const T* b, T* r) const {
    OffsetPoseError<D>(static_cast<const T*>(nullptr), b, nullptr, offset.data(), z.data(), r);
    WhitenInPlace<ErrorDim(D)>(W, r);
    return true;
  }
  Eigen::Matrix<double, Ambient(D), 1> z, offset;
  Eigen::Matrix<double, ErrorDim(D), ErrorDim(D)> W;
};

void CheckPose(const Eigen::VectorXd& x, const char* what) {
  BOXPLUS_CHECK(x.allFinite(), what, " must be finite");
  if (x.size() == 7) {
    BOXPLUS_CHECK(std::abs(x.tail<4>().norm() - 1.0) < 1e-9, what, ": quaternion is not unit");
  }
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeOffsetPose2D(const Eigen::Vector3d& z,
                                                      const Eigen::Vector3d& offset_a,
                                                      const Eigen::Vector3d& offset_b,
                                                      const NoiseModel& noise) {
  CheckPose(z, "offset pose 2D: measurement");
  CheckPose(offset_a, "offset pose 2D: first offset");
  CheckPose(offset_b, "offset pose 2D: second offset");
  return std::make_shared<ceres::AutoDiffCostFunction<OffsetPoseFunctor<2>, 3, 3, 3>>(
      new OffsetPoseFunctor<2>{z, offset_a, offset_b, noise.Fixed<3>("offset pose 2D")});
}

std::shared_ptr<ceres::CostFunction> MakeOffsetPose3D(const Eigen::Matrix<double, 7, 1>& z,
                                                      const Eigen::Matrix<double, 7, 1>& offset_a,
                                                      const Eigen::Matrix<double, 7, 1>& offset_b,
                                                      const NoiseModel& noise) {
  CheckPose(z, "offset pose 3D: measurement");
  CheckPose(offset_a, "offset pose 3D: first offset");
  CheckPose(offset_b, "offset pose 3D: second offset");
  return std::make_shared<ceres::AutoDiffCostFunction<OffsetPoseFunctor<3>, 6, 7, 7>>(
      new OffsetPoseFunctor<3>{z, offset_a, offset_b, noise.Fixed<6>("offset pose 3D")});
}

std::shared_ptr<ceres::CostFunction> MakeOffsetPosePrior2D(const Eigen::Vector3d& z,
                                                           const Eigen::Vector3d& offset,
                                                           const NoiseModel& noise) {
  CheckPose(z, "pose prior 2D: measurement");
  CheckPose(offset, "pose prior 2D: offset");
  return std::make_shared<ceres::AutoDiffCostFunction<OffsetPosePriorFunctor<2>, 3, 3>>(
      new OffsetPosePriorFunctor<2>{z, offset, noise.Fixed<3>("pose prior 2D")});
}

std::shared_ptr<ceres::CostFunction> MakeOffsetPosePrior3D(
    const Eigen::Matrix<double, 7, 1>& z, const Eigen::Matrix<double, 7, 1>& offset,
    const NoiseModel& noise) {
  CheckPose(z, "pose prior 3D: measurement");
  CheckPose(offset, "pose prior 3D: offset");
  return std::make_shared<ceres::AutoDiffCostFunction<OffsetPosePriorFunctor<3>, 6, 7>>(
      new OffsetPosePriorFunctor<3>{z, offset, noise.Fixed<6>("pose prior 3D")});
}

}  // namespace boxplus
