// Conversion of Python solve arguments into boxplus::SolverOptions (solver.cc).
#pragma once

#include <pybind11/pybind11.h>

#include "boxplus/solver_options.h"

namespace boxplus::python {

// `options` (None or a SolverOptions) with the keyword `overrides` applied
// (field names of SolverOptions, plus nonmonotonic_steps=n for
// use_nonmonotonic_steps/max_consecutive_nonmonotonic_steps); validated.
// Raises TypeError for unknown fields or wrong types, BoxplusError (ValueError)
// for values out of range.
SolverOptions MakeSolverOptions(const pybind11::object& options, const pybind11::dict& overrides);

}  // namespace boxplus::python
