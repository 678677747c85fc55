// Pinhole projection of all visible points of a calibration board at once.
//
// Residual (2N):  r_j = W (π(k, p_in_cam_j) − z_j),  j = 1..N,  W = L⁻¹, LLᵀ = Σ (pixels,
//   one 2×2 Σ shared by the points of the board)
//   p_in_cam_j = x2cam.fromlocal(x2world.tolocal(p_in_world_j))
// Parameter blocks: intrinsics k (the camera model's layout, see pinhole.h),
// x2world (SE3, 7), x2cam (SE3, 7); poses [p, q(x,y,z,w)], local → parent,
// tangent order [δp, δθ]. For a board, "world" is the board frame: x2world is
// the pose of the reference camera x in the board frame (cam2board), x2cam
// takes the reference camera to this camera (identity, fixed, for mono;
// left2right for the right camera of a stereo rig). Units: the board's (points)
// and pixels (z).
//
// The same measurements as N PinholePointFunctor factors, in one residual
// block: one autodiff pass per board, and a partial view passes only the
// visible points (the vertical-baseline rig).
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "boxplus/factors/pinhole.h"

namespace boxplus {

template <class Model>
class PinholeBoardFunctor {
 public:
  using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
  using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  PinholeBoardFunctor(const Points2& z, const Eigen::Matrix2d& sqrt_info, const Points3& p_in_world)
      : z_(z), W_(sqrt_info), p_(p_in_world) {}

  template <typename T>
  bool operator()(const T* k, const T* x2world, const T* x2cam, T* residual) const {
    for (Eigen::Index j = 0; j < p_.rows(); ++j) {
      const T p[3] = {T(p_(j, 0)), T(p_(j, 1)), T(p_(j, 2))};
      T p_in_cam[3];
      camera::ChainToCam(x2world, x2cam, p, p_in_cam);
      camera::ProjectionResidual<Model>(k, p_in_cam, z_.row(j).data(), W_, residual + 2 * j);
    }
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Points2& z, const Eigen::Matrix2d& W,
                                                     const Points3& p_in_world) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<PinholeBoardFunctor, ceres::DYNAMIC, Model::kSize, 7, 7>>(
        new PinholeBoardFunctor(z, W, p_in_world), 2 * static_cast<int>(z.rows()));
  }

 private:
  Points2 z_;
  Eigen::Matrix2d W_;
  Points3 p_;
};

// The board factor for a camera model named at run time; checks that z and
// p_in_world have the same number (≥ 1) of rows. Throws boxplus::Error.
std::shared_ptr<ceres::CostFunction> MakePinholeBoardFactor(
    const std::string& model, const PinholeBoardFunctor<camera::Pinhole>::Points2& z,
    const Eigen::Matrix2d& sqrt_info, const PinholeBoardFunctor<camera::Pinhole>::Points3& p_in_world);

}  // namespace boxplus
