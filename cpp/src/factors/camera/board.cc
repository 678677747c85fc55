#include "boxplus/factors/camera/board.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakeBoardFactor(const std::string& model, const BoardPixels& z,
                                                     const NoiseModel& noise,
                                                     const BoardPoints& p_in_world) {
  BOXPLUS_CHECK(z.rows() >= 1, "board factor: no points");
  BOXPLUS_CHECK(z.rows() == p_in_world.rows(), "board factor: ", z.rows(), " image points but ",
                p_in_world.rows(), " board points");
  BOXPLUS_CHECK(z.allFinite() && p_in_world.allFinite(), "board factor: non-finite points");
  const Eigen::Matrix2d W = noise.Fixed<2>("board factor");
  return camera::WithCameraModel(
      model, [&](auto m) { return BoardFunctor<decltype(m)>::Create(z, W, p_in_world); });
}

}  // namespace boxplus
