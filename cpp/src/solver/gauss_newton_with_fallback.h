// Gauss–Newton with a line search, falling back to Levenberg–Marquardt.
//
// Near a minimum of a small-residual problem Gauss–Newton's full step
// converges quadratically and costs one factorisation per iteration; a trust
// region there only adds rejected steps. Far from it, or where the problem is
// strongly non-linear (large rotation errors, wrong loop closures), the
// Gauss–Newton model is poor: the line search must shorten the step, and
// progress along a poor direction is slow. The line search tells which regime
// holds, so it decides the switch:
//   1. Gauss–Newton with the backtracking line search (method
//      kGaussNewtonLineSearch) while the full step α = 1 is accepted;
//   2. after `kShortenedStepsToSwitch` consecutive shortened steps (α < 1), or
//      when the line search finds no decrease, Levenberg–Marquardt (Ceres'
//      trust region with the options' damping, from the radius kFallbackRadius) from the last
//      accepted point for the remaining iterations.
// Measured on the generated pose-graph suite against the alternatives
// (bench/bench_pose_graph_suite.py; README "Pose graphs").
//
// The iteration callback and the verbose lines see one sequence of iterations
// (numbered on, times cumulative over both phases). Internal to
// boxplus::Problem (method kGaussNewtonFallback).
#pragma once

#include <functional>

#include "boxplus/solver_options.h"

namespace boxplus::internal {

inline constexpr int kShortenedStepsToSwitch = 3;
// The initial trust-region radius of the Levenberg–Marquardt phase (at most).
inline constexpr double kFallbackRadius = 1e4;

using SolveWith = std::function<SolveSummary(const SolverOptions&)>;

// `line_search` and `trust_region` solve the same problem from its current
// values with the given options (methods kGaussNewtonLineSearch and
// kLevenbergMarquardt).
SolveSummary SolveGaussNewtonWithFallback(const SolverOptions& options,
                                          const SolveWith& line_search,
                                          const SolveWith& trust_region);

}  // namespace boxplus::internal
