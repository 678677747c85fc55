#include "boxplus/factors/pose/bearing_range.h"

#include <ceres/autodiff_cost_function.h>

#include "boxplus/noise.h"

namespace boxplus {
namespace {

struct BearingRangeFunctor {
  template <typename T>
  bool operator()(const T* x, const T* l, T* r) const {
    Eigen::Matrix<T, 2, 1> e;
    if (!BearingRange2DError(x, l, z.data(), e.data())) return false;
    Eigen::Map<Eigen::Matrix<T, 2, 1>> r_map(r);
    r_map = U.cast<T>() * e;
    return true;
  }
  Eigen::Vector2d z;
  Eigen::Matrix2d U;
};

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeBearingRange2D(const Eigen::Vector2d& z,
                                                        const Eigen::Matrix2d& information) {
  BOXPLUS_CHECK(z.allFinite() && z[1] >= 0.0,
                "bearing-range: measurement must be finite with a range >= 0");
  const Eigen::Matrix2d U = NoiseModel::Information(information, "bearing-range").sqrt_information();
  return std::make_shared<ceres::AutoDiffCostFunction<BearingRangeFunctor, 2, 3, 2>>(
      new BearingRangeFunctor{z, U});
}

}  // namespace boxplus
