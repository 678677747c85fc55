// The one per-iteration progress format of boxplus: C++ verbose solves, the
// command-line tools and the Python module's verbose=True all print these
// lines. The objective is shown as χ² = Σ ρ(‖rᵢ‖²) = 2 × Ceres' cost (what g2o
// prints, and eᵀΩe summed over the measurements without a robust loss).
//
//   iter          chi2      change  |gradient|      |step|  radius/α      time
//      0  1.234567e+03
//      1  4.567890e+01  -1.189e+03   3.210e+01   1.000e-01  1.00e+16     0.012 s
#pragma once

#include <string>

#include "boxplus/solver_options.h"

namespace boxplus {

// The column titles (no trailing newline).
std::string ProgressHeader();
// One line for one iteration (no trailing newline). "change" is the change
// of χ² (negative when it falls); the last-but-one column is the trust-region
// radius, or the step length α of the line search.
std::string FormatProgress(const IterationInfo& info);
// The closing line of a solve, e.g.
// "convergence: chi2 1.234567e+03 -> 4.500470e+01 in 5 iterations, 0.009 s".
std::string FormatSummary(const SolveSummary& summary);

}  // namespace boxplus
