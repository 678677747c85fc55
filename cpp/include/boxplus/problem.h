// boxplus::Problem — a least-squares problem on ⊞-manifolds, solved by Ceres.
//
// Variables live on manifolds (any ceres::Manifold, typically the boxplus ones);
// boxplus owns their storage, their manifolds, and every cost and loss
// function: the underlying ceres::Problem is built with ownership switched
// off. Measurements are cost functions whose residual is already whitened,
// r = L⁻¹(h(Y) ⊟ z); the solver minimises ½ Σ ρ(‖r‖²) with ⊞ steps.
//
// Every input is validated here and raises boxplus::Error / IndexError
// naming the variable or measurement, so Ceres' aborting CHECKs are never
// reached.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>

namespace ceres {
class Problem;
}

namespace boxplus {

// Levenberg–Marquardt, Gauss–Newton and Powell's dogleg are Ceres' trust-region
// minimisers (kGaussNewton: undamped steps, a failed step only shrinks the
// region). kGaussNewtonLineSearch is boxplus' own Gauss–Newton with a
// backtracking line search along x ⊞ αδ (JᵀJ assembled by blocks, sparse
// Cholesky by Eigen or CHOLMOD; single-threaded; robust losses by reweighting).
enum class Method { kLevenbergMarquardt, kGaussNewton, kDogleg, kGaussNewtonLineSearch };

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
  double trust_region_radius = 0.0;  // line search: the step length α taken
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
  // Print one line per iteration (cost, change, time) to stderr.
  bool verbose = false;
  // Called after every iteration; return false to stop early (Ctrl-C). The
  // estimate is then the last accepted one.
  std::function<bool(const IterationInfo&)> on_iteration;
};

// The whitened residuals and their Jacobian at the current values, in the
// tangent spaces of the free (not fixed) variables (what the solver sees; with
// robust losses applied as Ceres applies them).
struct JacobianEvaluation {
  Eigen::VectorXd residuals;        // all measurements, in id order
  Eigen::MatrixXd jacobian;         // rows: residuals; columns: tangent coordinates
  std::vector<int> variables;       // free variables, in id order, one column block each
  std::vector<int> column_offsets;  // first column of each of `variables`
  std::vector<int> row_offsets;     // first row of each measurement
};

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

// Called before Ceres evaluates residuals at a new point or needs Jacobians;
// measurements that evaluate in bulk (vectorised Python functions) compute
// here and serve the per-measurement Evaluate calls from a cache.
using EvaluationHook = std::function<void(bool evaluate_jacobians, bool new_point)>;

class Problem {
 public:
  Problem();
  ~Problem();
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  // Adds a variable with initial value `init` (manifold->AmbientSize()
  // doubles) and returns its id (0, 1, 2, ... in order of addition).
  int AddVariable(std::shared_ptr<const ceres::Manifold> manifold,
                  const double* init, const std::string& name = "");
  int num_variables() const { return static_cast<int>(vars_.size()); }
  const std::string& variable_name(int id) const;
  const ceres::Manifold& manifold(int id) const;
  const double* value(int id) const;
  double* mutable_value(int id);
  void SetValue(int id, const double* ambient);
  void SetFixed(int id, bool fixed = true);
  bool IsFixed(int id) const;

  // Adds a measurement depending on `var_ids` (in the order of the cost
  // function's parameter blocks). `loss` may be null (plain least squares).
  int AddMeasurement(std::shared_ptr<ceres::CostFunction> cost,
                     const std::vector<int>& var_ids,
                     std::shared_ptr<ceres::LossFunction> loss = nullptr,
                     const std::string& name = "");
  int num_measurements() const;
  const std::string& measurement_name(int id) const;
  const std::vector<int>& measurement_variables(int id) const;
  int residual_size(int id) const;

  void AddEvaluationHook(EvaluationHook hook);

  SolveSummary Solve(const SolverOptions& options = {});

  // Whitened residual of one measurement at the current values.
  Eigen::VectorXd Residual(int measurement_id);
  // ½ Σ ρ(‖r‖²) at the current values.
  double Cost();

  // Dense Jacobian of every residual w.r.t. every free variable (for
  // diagnostics: rank, conditioning, which parameters are undetermined).
  JacobianEvaluation EvaluateJacobian();

  // Marginal covariance of a variable in its tangent space (after a solve).
  // Throws when the problem does not determine the variable (rank-deficient).
  Eigen::MatrixXd Covariance(int id);
  // Joint covariance of several variables, blocks in the order given.
  Eigen::MatrixXd JointCovariance(const std::vector<int>& ids);

  ceres::Problem& ceres_problem() { return *problem_; }

 private:
  struct Variable;
  struct Measurement;
  class HookDispatcher;
  void CheckVariable(int id) const;
  void CheckMeasurement(int id) const;
  SolveSummary SolveByLineSearch(const SolverOptions& options);

  std::unique_ptr<HookDispatcher> hooks_;
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<std::unique_ptr<Variable>> vars_;
  std::vector<Measurement> meas_;
};

}  // namespace boxplus
