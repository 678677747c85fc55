// boxplus' trust-region methods (Levenberg–Marquardt, Levenberg, dogleg,
// Gauss–Newton as an undamped LM) mapped onto ceres::Solve: SolverOptions to
// ceres::Solver::Options, ceres' iteration summaries to IterationInfo and the
// progress line of boxplus/progress.h, ceres' termination to SolveSummary.
//
// The variables are left at the last accepted point, also when the solve
// fails part-way or the iteration callback stops it.
//
// Internal to boxplus::Problem.
#pragma once

#include <vector>

#include <ceres/problem.h>

#include "boxplus/solver_options.h"
#include "least_squares.h"

namespace boxplus::internal {

// `blocks` are the variables of `problem` (for the snapshots of the accepted
// point); options.method must not be kGaussNewtonLineSearch.
SolveSummary SolveTrustRegion(ceres::Problem* problem, const std::vector<LsqBlock>& blocks,
                              const SolverOptions& options);

}  // namespace boxplus::internal
