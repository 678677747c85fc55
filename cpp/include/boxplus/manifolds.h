// Umbrella header: every manifold of boxplus, and a factory by name.
//
// Conventions (all manifolds): tangent order of poses is [translation,
// rotation]; quaternions are [x, y, z, w]; ⊞/⊟ as in each header.
#pragma once

#include <memory>
#include <string>

#include "boxplus/manifolds/ops_manifold.h"
#include "boxplus/manifolds/product.h"
#include "boxplus/manifolds/rn.h"
#include "boxplus/manifolds/s2.h"
#include "boxplus/manifolds/se2.h"
#include "boxplus/manifolds/se3.h"
#include "boxplus/manifolds/so2.h"
#include "boxplus/manifolds/so3.h"

namespace boxplus {

// "Rn" (with size n), "SO2", "SO3", "SE2", "SE3", "S2". Throws on an unknown
// name. Instances are stateless and may be shared between variables.
std::shared_ptr<const ceres::Manifold> MakeManifold(const std::string& kind, int n = 0);

}  // namespace boxplus
