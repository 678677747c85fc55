#include "boxplus/factors/pose/bearing_range.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/noise.h"

namespace boxplus {
namespace {

struct BearingRangeFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    if (!BearingRange2DError(x, l, z.data(), r)) return false;
    WhitenInPlace<2>(U, r);
    return true;
  }
  Eigen::Vector2d z;
  Eigen::Matrix2d U;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeBearingRange2D(const Eigen::Vector2d& z,
                                                        const NoiseModel& noise) {
  BOXPLUS_CHECK(z.allFinite() && z[1] >= 0.0,
                "bearing-range: measurement must be finite with a range >= 0");
  return std::make_shared<ceres::AutoDiffCostFunction<BearingRangeFunctor, 2, 3, 2>>(
      new BearingRangeFunctor{z, noise.Fixed<2>("bearing-range")});
}

}  // namespace boxplus
