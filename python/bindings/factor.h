// A measurement ready to be added to a problem, as the factor bindings make
// it: the cost function (whitened residual r = W e), the variables it depends
// on (ids, in the cost's parameter-block order) and the NoiseModel it whitens
// with. Every built-in factor of every domain is a function returning one of
// these (bindings/factors/<domain>.cc); Problem.add_factor is the one way
// into the problem, so a new factor is one function in one file.
#pragma once

#include <memory>
#include <vector>

#include <ceres/cost_function.h>

#include "boxplus/noise.h"

namespace boxplus::python {

struct Factor {
  std::shared_ptr<ceres::CostFunction> cost;
  std::vector<int> variables;
  NoiseModel noise;
};

}  // namespace boxplus::python
