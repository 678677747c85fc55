// Solver settings, the per-iteration record and the result of a solve: one
// vocabulary for boxplus::Problem, the pose graph, the command line and the
// Python module (bound as classes there), with one parser for each name.
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace boxplus {

// Levenberg–Marquardt, Gauss–Newton and Powell's dogleg are Ceres' trust-region
// minimisers (kGaussNewton: undamped steps, a failed step only shrinks the
// region). kGaussNewtonLineSearch is boxplus' own Gauss–Newton with a
// backtracking line search along x ⊞ αδ (JᵀJ assembled by blocks, sparse
// Cholesky by Eigen or CHOLMOD; num_threads share the Jacobians; robust losses by reweighting).
// kGaussNewtonFallback runs kGaussNewtonLineSearch while its full steps are
// accepted and switches to kLevenbergMarquardt when the line search has to
// shorten them (see src/solver/gauss_newton_with_fallback.h): the pose-graph
// default, chosen on the generated suite.
enum class Method {
  kLevenbergMarquardt,
  kGaussNewton,
  kDogleg,
  kGaussNewtonLineSearch,
  kGaussNewtonFallback
};

// The damping matrix D of a Levenberg–Marquardt step (JᵀJ + D/μ) δ = −Jᵀr,
// μ the trust-region radius:
//   kMarquardt  D = diag(JᵀJ), clamped to [1e-6, 1e32] (Ceres' default);
//   kLevenberg  D = I, i.e. λI damping with λ = 1/μ (g2o's LM); with
//               jacobi_scaling the identity is in the scaled coordinates.
enum class Damping { kMarquardt, kLevenberg };

// What the per-iteration callback sees.
struct IterationInfo {
  int iteration = 0;
  double cost = 0.0;  // ½ Σ ρ(‖r‖²)
  double cost_change = 0.0;
  double gradient_max_norm = 0.0;
  double step_norm = 0.0;
  double trust_region_radius = 0.0;  // trust-region methods; 0 for the line search
  double step_length = 1.0;          // the line search's α (1 for trust regions)
  double iteration_time_s = 0.0;
  double cumulative_time_s = 0.0;
  bool step_is_successful = false;
};

struct SolverOptions {
  Method method = Method::kLevenbergMarquardt;
  int max_iterations = 100;
  double function_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-10;
  int num_threads = 1;
  // Trust-region strategy (Levenberg–Marquardt and Gauss–Newton; see Ceres'
  // Solver::Options). A very large initial radius starts like Gauss–Newton
  // and damps only after a step fails (each failure divides the radius by a
  // factor that doubles on consecutive failures; a success grows it).
  double initial_trust_region_radius = 1e4;
  Damping damping = Damping::kMarquardt;
  // Scale the columns of J by 1/(1 + ‖J_k‖) before solving.
  bool jacobi_scaling = true;
  // Accept steps that increase the cost while the best cost seen in the last
  // few steps still decreases enough (Ceres' use_nonmonotonic_steps).
  bool use_nonmonotonic_steps = false;
  int max_consecutive_nonmonotonic_steps = 5;
  // Print one line per iteration (FormatProgress, progress.h) to stderr.
  bool verbose = false;
  // Called after every iteration; return false to stop early (Ctrl-C). The
  // estimate is then the last accepted one.
  std::function<bool(const IterationInfo&)> on_iteration;
  // Asked within an iteration, between its phases (after the factorisation,
  // before each line-search trial), by the solvers that can stop there (gn_ls
  // and the Gauss–Newton phase of gn_lm; Ceres' trust-region methods only call
  // on_iteration): true stops the solve with the last accepted estimate
  // (termination "interrupted"), so Ctrl-C on a large graph waits for one
  // linear solve, not a whole iteration.
  std::function<bool()> should_stop;
  // The fields the caller set, by name (SolverOptionNames()), when the caller
  // says which (Python always does: keywords, assignments, overrides): an owner
  // with defaults of its own (PoseGraph::Solve) takes these fields from the
  // caller and its own defaults for the rest, so that a field given one way or
  // another (method="lm" as a keyword or in a SolverOptions) solves the same.
  // Unset: every field is the caller's (a C++ caller that starts from the
  // owner's defaults, as boxplus-g2o does from slam::DefaultSolverOptions()).
  std::optional<std::set<std::string>> given;
};

// The names of SolverOptions' settable fields (the Python attributes and
// keywords; "given" and the callbacks are not settings).
const std::vector<std::string>& SolverOptionNames();

// `defaults` with the fields in options.given taken from `options` (and its
// callbacks); `options` itself when it names no fields (given unset). Throws
// boxplus::Error for a name that is not a field.
SolverOptions WithDefaults(const SolverOptions& defaults, const SolverOptions& options);

struct SolveSummary {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  double time_s = 0.0;
  std::string termination;  // "convergence", "no_convergence", "interrupted", "failure"
  std::string message;      // Ceres' own explanation
  bool usable = false;      // the estimate may be used (converged or stopped early)
  std::string report;       // Ceres' full report
};

// Names on input (case-insensitive; '-' reads as '_'): "lm" /
// "levenberg_marquardt", "gn" / "gauss_newton", "gn_ls", "dogleg", "gn_lm" /
// "auto" (kGaussNewtonFallback). Throws boxplus::Error naming
// the accepted ones.
Method ParseMethod(const std::string& name);
// "lm", "gn", "gn_ls", "dogleg", "gn_lm".
std::string MethodName(Method method);
const std::vector<std::string>& MethodNames();

// "marquardt" or "levenberg"; throws boxplus::Error otherwise.
Damping ParseDamping(const std::string& name);
std::string DampingName(Damping damping);

// Checks every field (ranges, finiteness); throws boxplus::Error naming it.
void Validate(const SolverOptions& options);

}  // namespace boxplus
