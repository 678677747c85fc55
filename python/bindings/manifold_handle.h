// A Python-visible handle on a ceres::Manifold (built-in, compound, or one
// defined in Python), shared between the variables that use it.
#pragma once

#include <memory>
#include <string>

#include <ceres/loss_function.h>
#include <ceres/manifold.h>

namespace boxplus::python {

struct ManifoldHandle {
  std::shared_ptr<const ceres::Manifold> manifold;
  std::string kind;  // "SO3", "Rn", "Compound", "Python", ...
};

// A robust loss shared by the measurements that use it (null: least squares).
struct LossHandle {
  std::shared_ptr<ceres::LossFunction> loss;
  std::string description;
};

}  // namespace boxplus::python
