#include "gauss_newton_with_fallback.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "boxplus/progress.h"
#include "gauss_newton_line_search.h"

namespace boxplus::internal {

SolveSummary SolveGaussNewtonWithFallback(const SolverOptions& options,
                                          const SolveWith& line_search,
                                          const SolveWith& trust_region) {
  // The phases report through this one callback, so that the user sees one
  // numbered sequence and one header.
  bool user_stopped = false, switch_now = false;
  int shortened = 0, iteration_offset = 0;
  double time_offset = 0.0;
  auto report = [&](IterationInfo info) {
    if (iteration_offset > 0 && info.iteration == 0) return true;  // the LM restart point
    info.iteration += iteration_offset;
    info.cumulative_time_s += time_offset;
    if (options.verbose) {
      if (info.iteration == 0) std::fprintf(stderr, "%s\n", ProgressHeader().c_str());
      std::fprintf(stderr, "%s\n", FormatProgress(info).c_str());
    }
    if (options.on_iteration && !options.on_iteration(info)) {
      user_stopped = true;
      return false;
    }
    return true;
  };

  SolverOptions gn = options;
  gn.method = Method::kGaussNewtonLineSearch;
  gn.verbose = false;
  gn.on_iteration = [&](const IterationInfo& info) {
    if (!report(info)) return false;
    if (info.iteration > 0) shortened = info.step_length < 1.0 ? shortened + 1 : 0;
    if (shortened >= kShortenedStepsToSwitch) {
      switch_now = true;
      return false;
    }
    return true;
  };
  SolveSummary first = line_search(gn);
  const bool no_decrease =
      first.termination == "convergence" && first.message == kNoDecreaseMessage;
  if (user_stopped || !first.usable || !(switch_now || no_decrease) ||
      first.iterations >= options.max_iterations) {
    if (switch_now && !user_stopped) {
      first.termination = "no_convergence";
      first.message = "maximum number of iterations reached";
    }
    return first;
  }

  SolverOptions lm = options;
  lm.method = Method::kLevenbergMarquardt;
  lm.verbose = false;
  lm.max_iterations = options.max_iterations - first.iterations;
  // Undamped steps have just failed: start damped, at Ceres' default radius,
  // not at a radius that would retry Gauss-Newton's step (measured: 1e16
  // needed 27 iterations where 1e4 needed 16 on a 2D torus at bignoise).
  lm.initial_trust_region_radius = std::min(options.initial_trust_region_radius, kFallbackRadius);
  iteration_offset = first.iterations;
  time_offset = first.time_s;
  lm.on_iteration = report;
  SolveSummary second = trust_region(lm);

  SolveSummary out = second;
  out.initial_cost = first.initial_cost;
  out.iterations = first.iterations + second.iterations;
  out.time_s = first.time_s + second.time_s;
  out.message = "Gauss-Newton with line search for " + std::to_string(first.iterations) +
                " iterations (" +
                (switch_now ? std::to_string(kShortenedStepsToSwitch) + " shortened steps"
                            : "no decrease along its direction") +
                "), then Levenberg-Marquardt: " + second.message;
  out.report = first.report + second.report;
  return out;
}

}  // namespace boxplus::internal
