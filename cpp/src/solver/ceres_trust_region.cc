#include "ceres_trust_region.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include <ceres/iteration_callback.h>
#include <ceres/solver.h>

#include "boxplus/errors.h"
#include "boxplus/progress.h"

namespace boxplus::internal {
namespace {

class CallbackAdapter final : public ceres::IterationCallback {
 public:
  CallbackAdapter(const SolverOptions& options, bool* interrupted,
                  std::function<void()> on_accepted)
      : options_(options), interrupted_(interrupted), on_accepted_(std::move(on_accepted)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    // update_state_every_iteration: the variables hold the best point now.
    if (s.iteration == 0 || s.step_is_successful) on_accepted_();
    IterationInfo info;
    info.iteration = s.iteration;
    info.cost = s.cost;
    info.cost_change = s.cost_change;
    info.gradient_max_norm = s.gradient_max_norm;
    info.step_norm = s.step_norm;
    info.trust_region_radius = s.trust_region_radius;
    info.iteration_time_s = s.iteration_time_in_seconds;
    info.cumulative_time_s = s.cumulative_time_in_seconds;
    info.step_is_successful = s.step_is_successful;
    if (options_.verbose) {
      if (s.iteration == 0) std::fprintf(stderr, "%s\n", ProgressHeader().c_str());
      std::fprintf(stderr, "%s\n", FormatProgress(info).c_str());
    }
    if (options_.on_iteration && !options_.on_iteration(info)) {
      *interrupted_ = true;
      // Keep the last accepted estimate (written back on return).
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const SolverOptions& options_;
  bool* interrupted_;
  std::function<void()> on_accepted_;
};

ceres::Solver::Options CeresOptions(const SolverOptions& options) {
  ceres::Solver::Options o;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  BOXPLUS_CHECK(options.initial_trust_region_radius > 0, "initial_trust_region_radius must be > 0");
  BOXPLUS_CHECK(options.max_consecutive_nonmonotonic_steps >= 0,
                "max_consecutive_nonmonotonic_steps must be >= 0");
  o.initial_trust_region_radius = options.initial_trust_region_radius;
  o.max_trust_region_radius = std::max(o.max_trust_region_radius, o.initial_trust_region_radius);
  if (options.damping == Damping::kLevenberg) {
    o.min_lm_diagonal = 1.0;
    o.max_lm_diagonal = 1.0;
  }
  o.jacobi_scaling = options.jacobi_scaling;
  o.use_nonmonotonic_steps = options.use_nonmonotonic_steps;
  o.max_consecutive_nonmonotonic_steps = options.max_consecutive_nonmonotonic_steps;
  switch (options.method) {
    case Method::kLevenbergMarquardt:
      break;
    case Method::kDogleg:
      o.trust_region_strategy_type = ceres::DOGLEG;
      break;
    case Method::kGaussNewton:
      // Undamped normal equations; the trust region only rejects steps that
      // increase the cost.
      o.min_lm_diagonal = 1e-32;
      o.max_lm_diagonal = 1e-32;
      o.initial_trust_region_radius = 1e16;
      o.max_trust_region_radius = 1e16;
      break;
    case Method::kGaussNewtonLineSearch:
    case Method::kGaussNewtonFallback:
      throw Error("the line search is not a trust-region method");
  }
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.max_num_iterations = options.max_iterations;
  o.function_tolerance = options.function_tolerance;
  o.gradient_tolerance = options.gradient_tolerance;
  o.parameter_tolerance = options.parameter_tolerance;
  o.num_threads = options.num_threads;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.update_state_every_iteration = true;
  return o;
}

}  // namespace

SolveSummary SolveTrustRegion(ceres::Problem* problem, const std::vector<LsqBlock>& blocks,
                              const SolverOptions& options) {
  ceres::Solver::Options o = CeresOptions(options);
  bool interrupted = false;
  // The last accepted point: restored when the solve fails part-way (an
  // evaluation error, Ctrl-C inside a measurement function), so the variables
  // never hold a rejected trial point.
  std::vector<std::vector<double>> best(blocks.size());
  auto snapshot = [&blocks, &best] {
    for (size_t i = 0; i < blocks.size(); ++i) {
      best[i].assign(blocks[i].x, blocks[i].x + blocks[i].manifold->AmbientSize());
    }
  };
  snapshot();
  CallbackAdapter callback(options, &interrupted, snapshot);
  o.callbacks.push_back(&callback);
  std::string why;
  BOXPLUS_CHECK(o.IsValid(&why), "invalid solver options: ", why);

  ceres::Solver::Summary s;
  ceres::Solve(o, problem, &s);
  SolveSummary out;
  out.initial_cost = s.initial_cost;
  out.final_cost = s.final_cost;
  out.iterations = static_cast<int>(s.iterations.size()) - 1;
  out.time_s = s.total_time_in_seconds;
  out.message = s.message;
  out.report = s.FullReport();
  if (interrupted) {
    out.termination = "interrupted";
    out.usable = true;
  } else if (s.termination_type == ceres::CONVERGENCE) {
    out.termination = "convergence";
    out.usable = true;
  } else if (s.termination_type == ceres::NO_CONVERGENCE) {
    out.termination = "no_convergence";
    out.usable = true;
  } else {
    out.termination = "failure";
    out.usable = false;
  }
  const bool finite = std::isfinite(s.initial_cost) && std::isfinite(s.final_cost);
  if (interrupted || s.termination_type == ceres::FAILURE || !finite) {
    for (size_t i = 0; i < blocks.size(); ++i) {
      std::copy(best[i].begin(), best[i].end(), blocks[i].x);
    }
    out.final_cost = std::min(out.final_cost, out.initial_cost);
  }
  return out;
}

}  // namespace boxplus::internal
