// A Python-visible handle on a ceres::Manifold (built-in, compound, or one
// defined in Python), shared between the variables that use it.
#pragma once

#include <memory>
#include <string>

#include <ceres/manifold.h>

namespace boxplus::python {

struct ManifoldHandle {
  std::shared_ptr<const ceres::Manifold> manifold;
  std::string kind;  // "SO3", "Rn", "Compound", "Python", ...
};

}  // namespace boxplus::python
