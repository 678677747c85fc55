#include "manifold_domain.h"

#include <cmath>

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/manifolds.h"

namespace boxplus::internal {
namespace {

void NormaliseUnit(double* v, int n, const char* kind, const DescribeValue& what) {
  Eigen::Map<Eigen::VectorXd> x(v, n);
  const double norm = x.stableNorm();
  BOXPLUS_CHECK(norm > 0.0, what(), ": the ", kind, " is zero");
  BOXPLUS_CHECK(std::isfinite(norm) && std::abs(norm - 1.0) <= kUnitTolerance, what(), ": the ",
                kind, " has norm ", norm, ", not 1 (within ", kUnitTolerance, ")");
  x /= norm;
}

}  // namespace

void NormaliseAmbient(const ceres::Manifold& manifold, double* x, const DescribeValue& what) {
  if (dynamic_cast<const SO3Manifold*>(&manifold)) {
    NormaliseUnit(x, 4, "quaternion [x, y, z, w]", what);
  } else if (dynamic_cast<const SE3Manifold*>(&manifold)) {
    NormaliseUnit(x + 3, 4, "quaternion [x, y, z, w] (ambient entries 3-6)", what);
  } else if (dynamic_cast<const S2Manifold*>(&manifold)) {
    NormaliseUnit(x, 3, "unit vector", what);
  } else if (const auto* product = dynamic_cast<const ProductManifold*>(&manifold)) {
    for (int i = 0; i < product->num_members(); ++i) {
      NormaliseAmbient(product->member(i), x + product->ambient_offset(i),
                       [&what, i] { return what() + ", member " + std::to_string(i); });
    }
  }
}

bool IsEuclidean(const ceres::Manifold& manifold) {
  if (dynamic_cast<const RnManifold*>(&manifold)) return true;
  if (const auto* product = dynamic_cast<const ProductManifold*>(&manifold)) {
    for (int i = 0; i < product->num_members(); ++i) {
      if (!IsEuclidean(product->member(i))) return false;
    }
    return product->num_members() > 0;
  }
  return false;
}

}  // namespace boxplus::internal
