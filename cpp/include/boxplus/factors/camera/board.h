// Projection of all visible points of a calibration board at once.
//
// Residual (2N):  r_j = W (π(k, p_in_cam_j) − z_j),  j = 1..N,  WᵀW = Σ⁻¹ (pixels,
//   one 2-dim NoiseModel shared by the points of the board, block-diagonal W)
//   p_in_cam_j = cam_from_rig · world_from_rig⁻¹ · p_in_world_j   (camera::ChainToCam)
// Parameter blocks: intrinsics k (the camera model's layout, see models.h),
// world_from_rig (SE3, 7), cam_from_rig (SE3, 7); poses [p, q(x,y,z,w)],
// tangent order [δp, δθ]. For a board, "world" is the board frame:
// world_from_rig is the pose of the reference camera in the board frame
// (board_from_cam for one camera), cam_from_rig takes the reference camera to
// this camera (identity, fixed, for mono; right_from_left for the right camera
// of a stereo rig). Units: the board's (points) and pixels (z).
//
// The same measurements as N PointProjectionFunctor factors (point_projection.h),
// in one residual block: one autodiff pass per board, and a partial view passes
// only the visible points (the vertical-baseline rig).
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "boxplus/factors/camera/point_projection.h"

namespace boxplus {

using BoardPixels = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
using BoardPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

template <class Model>
class BoardFunctor {
 public:
  BoardFunctor(const BoardPixels& z, const Eigen::Matrix2d& W, const BoardPoints& p_in_world)
      : z_(z), W_(W), p_in_world_(p_in_world) {}

  template <typename T>
  bool operator()(const T* k, const T* world_from_rig, const T* cam_from_rig, T* residual) const {
    for (Eigen::Index j = 0; j < p_in_world_.rows(); ++j) {
      const T p[3] = {T(p_in_world_(j, 0)), T(p_in_world_(j, 1)), T(p_in_world_(j, 2))};
      T p_in_cam[3];
      camera::ChainToCam(world_from_rig, cam_from_rig, p, p_in_cam);
      camera::ProjectionResidual<Model>(k, p_in_cam, z_.row(j).data(), W_, residual + 2 * j);
    }
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const BoardPixels& z, const Eigen::Matrix2d& W,
                                                     const BoardPoints& p_in_world) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<BoardFunctor, ceres::DYNAMIC, Model::kSize, 7, 7>>(
        new BoardFunctor(z, W, p_in_world), 2 * static_cast<int>(z.rows()));
  }

 private:
  BoardPixels z_;
  Eigen::Matrix2d W_;
  BoardPoints p_in_world_;
};

// The board factor for a camera model named at run time; `noise` of dimension
// 2 (one corner, pixels). Checks that z and p_in_world have the same number
// (≥ 1) of rows and are finite. Throws boxplus::Error.
std::shared_ptr<ceres::CostFunction> MakeBoardFactor(const std::string& model, const BoardPixels& z,
                                                     const NoiseModel& noise,
                                                     const BoardPoints& p_in_world);

}  // namespace boxplus
