#include "boxplus/factors/pose/relative_pose.h"

#include <ceres/autodiff_cost_function.h>

#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "relative_pose_analytic.h"

namespace boxplus {
namespace {

// r = W e in convention C for SE(D) poses (error of N = 3 or 6 entries).
template <int D, class C>
struct RelativePoseFunctor {
  static constexpr int N = D == 2 ? 3 : 6;
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    if constexpr (D == 2) {
      RelativePose2DError<C>(xi, xj, z.data(), r);
    } else {
      RelativePose3DError<C>(xi, xj, z.data(), r);
    }
    WhitenInPlace<N>(W, r);
    return true;
  }
  Eigen::Matrix<double, D == 2 ? 3 : 7, 1> z;
  Eigen::Matrix<double, N, N> W;
};

// z with its quaternion normalised (overflow-safe). The compound ⊟ takes a
// unit z as given, so that callers who normalised it already (Python's
// add_relative_pose) keep their exact value; the Δ conventions normalise
// always, as g2o does when it reads an edge.
Eigen::Matrix<double, 7, 1> UnitPose(const Eigen::Matrix<double, 7, 1>& z,
                                     PoseErrorConvention convention) {
  BOXPLUS_CHECK(z.allFinite(), "relative pose 3D: measurement must be finite");
  if (convention == PoseErrorConvention::kCompound &&
      std::abs(z.tail<4>().squaredNorm() - 1.0) <= 1e-12) {
    return z;
  }
  Eigen::Matrix<double, 7, 1> out = z;
  BOXPLUS_CHECK(NormalizeQuaternion(z.data() + 3, out.data() + 3),
                "relative pose 3D: measured quaternion has zero norm");
  return out;
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeRelativePose2D(const Eigen::Vector3d& z,
                                                        const NoiseModel& noise,
                                                        PoseErrorConvention convention) {
  if (convention != PoseErrorConvention::kG2o) {
    return MakeRelativePose2DAutoDiff(z, noise, convention);
  }
  BOXPLUS_CHECK(z.allFinite(), "relative pose 2D: measurement must be finite");
  return internal::MakeRelativePose2DG2oAnalytic(z, noise.Fixed<3>("relative pose 2D"));
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose2DAutoDiff(const Eigen::Vector3d& z,
                                                                const NoiseModel& noise,
                                                                PoseErrorConvention convention) {
  if (convention == PoseErrorConvention::kSESync) return MakeChordalRelativePose2D(z, noise);
  BOXPLUS_CHECK(z.allFinite(), "relative pose 2D: measurement must be finite");
  const Eigen::Matrix3d W = noise.Fixed<3>("relative pose 2D");
  std::shared_ptr<ceres::CostFunction> cost;
  WithErrorConvention(convention, [&](auto tag) {
    using F = RelativePoseFunctor<2, decltype(tag)>;
    cost = std::make_shared<ceres::AutoDiffCostFunction<F, 3, 3, 3>>(new F{z, W});
  });
  return cost;
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose3D(const Eigen::Matrix<double, 7, 1>& z,
                                                        const NoiseModel& noise,
                                                        PoseErrorConvention convention) {
  if (convention != PoseErrorConvention::kG2o && convention != PoseErrorConvention::kLog) {
    return MakeRelativePose3DAutoDiff(z, noise, convention);
  }
  const Eigen::Matrix<double, 6, 6> W = noise.Fixed<6>("relative pose 3D");
  const Eigen::Matrix<double, 7, 1> zu = UnitPose(z, convention);
  return convention == PoseErrorConvention::kG2o ? internal::MakeRelativePose3DG2oAnalytic(zu, W)
                                                 : internal::MakeRelativePose3DLogAnalytic(zu, W);
}

std::shared_ptr<ceres::CostFunction> MakeRelativePose3DAutoDiff(
    const Eigen::Matrix<double, 7, 1>& z, const NoiseModel& noise, PoseErrorConvention convention) {
  if (convention == PoseErrorConvention::kSESync) return MakeChordalRelativePose3D(z, noise);
  const Eigen::Matrix<double, 6, 6> W = noise.Fixed<6>("relative pose 3D");
  const Eigen::Matrix<double, 7, 1> zu = UnitPose(z, convention);
  std::shared_ptr<ceres::CostFunction> cost;
  WithErrorConvention(convention, [&](auto tag) {
    using F = RelativePoseFunctor<3, decltype(tag)>;
    cost = std::make_shared<ceres::AutoDiffCostFunction<F, 6, 7, 7>>(new F{zu, W});
  });
  return cost;
}

}  // namespace boxplus
