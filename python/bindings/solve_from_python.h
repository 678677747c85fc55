// The one way a solve starts from Python: options from a SolverOptions and
// keywords, Python manifolds validated first, the GIL released while C++
// solves, the callback and Ctrl-C checked between iterations, and a Python
// error raised inside (a measurement function, a manifold, the callback)
// re-raised afterwards with its traceback. Problem.solve and PoseGraph.solve
// both go through it.
#pragma once

#include <functional>
#include <string>

#include <pybind11/pybind11.h>

#include "boxplus/problem.h"
#include "boxplus/solver_options.h"

namespace boxplus::python {

// "variable 'name'" (or "variable <id>") for messages.
std::string VariableWhat(const Problem& problem, int id);

// `solve` runs the C++ solve of `problem` (or of what owns it) with the
// options built here.
SolveSummary SolveFromPython(Problem& problem, const pybind11::object& options,
                             const pybind11::object& callback, const pybind11::kwargs& overrides,
                             const std::function<SolveSummary(const SolverOptions&)>& solve);

}  // namespace boxplus::python
