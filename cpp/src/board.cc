#include "boxplus/factors/board.h"

#include "boxplus/errors.h"

namespace boxplus {

std::shared_ptr<ceres::CostFunction> MakePinholeBoardFactor(
    const std::string& model, const PinholeBoardFunctor<camera::Pinhole>::Points2& z,
    const Eigen::Matrix2d& W, const PinholeBoardFunctor<camera::Pinhole>::Points3& p) {
  BOXPLUS_CHECK(z.rows() >= 1, "board factor: no points");
  BOXPLUS_CHECK(z.rows() == p.rows(), "board factor: ", z.rows(), " image points but ", p.rows(),
                " board points");
  BOXPLUS_CHECK(z.allFinite() && p.allFinite(), "board factor: non-finite points");
  return camera::WithCameraModel(model, [&](auto m) {
    return PinholeBoardFunctor<decltype(m)>::Create(z, W, p);
  });
}

}  // namespace boxplus
