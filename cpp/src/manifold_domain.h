// The domain of each boxplus manifold's ambient values, checked where values
// enter a Problem: unit quaternions on SO(3) and SE(3), unit vectors on S².
//
// Internal to boxplus::Problem.
#pragma once

#include <functional>
#include <string>

#include <ceres/manifold.h>

namespace boxplus::internal {

// Relative distance from unit norm below which a quaternion or direction is
// taken as unit and normalised (values printed with 3–4 decimals pass); above
// it the value is refused as not a rotation or direction.
constexpr double kUnitTolerance = 1e-3;

// Names the value in a message; called only when one is written (values of
// 10⁵–10⁶ pose-graph vertices pass through here).
using DescribeValue = std::function<std::string()>;

// Normalises the unit parts of `x` (ambient values of `manifold`; members of
// a boxplus::ProductManifold too) in place. Norms are computed with scaling
// (no overflow for components of 1e200). Throws boxplus::Error naming `what()`
// when a part is zero, not finite or farther than kUnitTolerance from unit.
void NormaliseAmbient(const ceres::Manifold& manifold, double* x, const DescribeValue& what);

// True when x ⊞ δ = x + δ (RnManifold and products of them only): Ceres then
// needs no manifold, and no Plus Jacobian is stored.
bool IsEuclidean(const ceres::Manifold& manifold);

}  // namespace boxplus::internal
