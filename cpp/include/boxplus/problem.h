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
//
// One thread at a time: while Solve runs, a call from another thread that
// solves, evaluates or modifies the problem throws boxplus::Error ("problem
// is already being solved in another thread") instead of racing; reading
// values is always allowed.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "boxplus/determinedness.h"
#include "boxplus/noise.h"
#include "boxplus/solver_options.h"

namespace ceres {
class Problem;
}

namespace boxplus {

// The whitened residuals and their Jacobian at the current values, in the
// tangent spaces of the free (not fixed) variables (what the solver sees; with
// robust losses applied as Ceres applies them).
// The whitened Jacobian with the layout of JacobianEvaluation, sparse.
struct SparseJacobianEvaluation {
  Eigen::VectorXd residuals;  // all measurements, in id order
  Eigen::SparseMatrix<double> jacobian;
  std::vector<int> variables;
  std::vector<int> column_offsets;
};

struct JacobianEvaluation {
  Eigen::VectorXd residuals;        // all measurements, in id order
  Eigen::MatrixXd jacobian;         // rows: residuals; columns: tangent coordinates
  std::vector<int> variables;       // free variables, in id order, one column block each
  std::vector<int> column_offsets;  // first column of each of `variables`
  std::vector<int> row_offsets;     // first row of each measurement
};

// Called before Ceres evaluates residuals at a new point or needs Jacobians;
// measurements that evaluate in bulk (vectorised Python functions) compute
// here and serve the per-measurement Evaluate calls from a cache.
using EvaluationHook = std::function<void(bool evaluate_jacobians, bool new_point)>;

// Names the measurements added without a name, from their id ("" when it has
// none for that id: the name is then "z<id>"). Lets an owner whose
// measurements are named by their data (a pose graph's "edge i-j") keep no
// string per measurement.
using MeasurementNamer = std::function<std::string(int measurement_id)>;

class Problem {
 public:
  Problem();
  ~Problem();
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  // Room for this many variables and measurements (a pose graph knows its
  // size), so adding them needs no regrowth of the storage.
  void Reserve(int variables, int measurements);

  // Adds a variable with initial value `init` (manifold->AmbientSize()
  // doubles) and returns its id (0, 1, 2, ... in order of addition).
  // Values on SO(3), SE(3) and S² (also as members of a ProductManifold) must
  // be unit within 10⁻³ and are normalised; zero or far from unit throws.
  // Plain Rⁿ (RnManifold) is passed to Ceres as Euclidean: no n × n Plus
  // Jacobian is stored.
  int AddVariable(std::shared_ptr<const ceres::Manifold> manifold, const double* init,
                  const std::string& name = "");
  int num_variables() const { return static_cast<int>(vars_.size()); }
  // Changes whenever values, fixed flags, variables or measurements change: a result
  // computed at one generation (a covariance, a report) is still valid while it holds.
  long long generation() const { return generation_; }
  const std::string& variable_name(int id) const;
  const ceres::Manifold& manifold(int id) const;
  const double* value(int id) const;
  // Validated and normalised as in AddVariable.
  void SetValue(int id, const double* ambient);
  void SetFixed(int id, bool fixed = true);
  bool IsFixed(int id) const;
  // True when some measurement depends on the variable. A free variable no
  // measurement touches is undetermined: it has no covariance.
  bool IsTouched(int id) const;
  // Names of the variable's tangent directions (e.g. "x", "rotation about
  // z"), used when a message names an undetermined direction; empty: "d0",
  // "d1", ...
  void SetDirectionLabels(int id, std::vector<std::string> labels);
  const std::vector<std::string>& direction_labels(int id) const;

  // Adds a measurement depending on `var_ids` (in the order of the cost
  // function's parameter blocks). The cost function returns the whitened
  // residual r = W e; `noise` is the W it whitens with, kept so that Error()
  // can un-whiten (its dimension must divide the residual size; a default
  // NoiseModel means the residual is the error). `loss` may be null (plain
  // least squares). A measurement must depend on at least one variable, each
  // listed once, and its Jacobians must fit Ceres' int-indexed storage.
  int AddMeasurement(std::shared_ptr<ceres::CostFunction> cost, std::vector<int> var_ids,
                     NoiseModel noise, std::shared_ptr<ceres::LossFunction> loss = nullptr,
                     const std::string& name = "");
  int AddMeasurement(std::shared_ptr<ceres::CostFunction> cost, const std::vector<int>& var_ids,
                     std::shared_ptr<ceres::LossFunction> loss = nullptr,
                     const std::string& name = "") {
    return AddMeasurement(std::move(cost), var_ids, NoiseModel(), std::move(loss), name);
  }
  int num_measurements() const;
  // The name given to AddMeasurement, else the namer's, else "z<id>".
  std::string measurement_name(int id) const;
  void SetMeasurementNamer(MeasurementNamer namer);
  const std::vector<int>& measurement_variables(int id) const;
  int residual_size(int id) const;
  // The noise model the measurement whitens with.
  const NoiseModel& noise(int id) const;

  void AddEvaluationHook(EvaluationHook hook);

  // Minimises the cost from the current values. A cost that is not finite
  // at the start or at the end is a "failure" (the message names the first
  // measurement whose residual is not finite).
  SolveSummary Solve(const SolverOptions& options = {});

  // Whitened residual r = W e of one measurement at the current values.
  Eigen::VectorXd Residual(int measurement_id);
  // Its error e = W⁻¹ r in the measurement's own units (pixels, metres...).
  Eigen::VectorXd Error(int measurement_id);
  // The errors (or, `whitened`, the residuals) of several measurements,
  // concatenated in the order given; the evaluation hooks run once for all of
  // them (Error() per measurement would run them once each).
  Eigen::VectorXd Errors(const std::vector<int>& measurement_ids, bool whitened = false);
  // ½ Σ ρ(‖r‖²) at the current values.
  double Cost();

  // Dense Jacobian of every residual w.r.t. every free variable (for
  // diagnostics: rank, conditioning, which parameters are undetermined).
  JacobianEvaluation EvaluateJacobian();

  SparseJacobianEvaluation EvaluateSparseJacobian();

  // Which tangent directions of the free variables the measurements leave
  // undetermined at the current values (determinedness.h: a rank test on the
  // equilibrated Jacobian, one sparse factorisation). Kept until the problem
  // or its values change, so the covariances after a solve share it.
  const Determinedness& CheckDetermined(const DeterminednessOptions& options = {});

  // Marginal covariance of a variable in its tangent space (after a solve).
  // Throws when the problem does not determine the variable: it is fixed, no
  // measurement touches it (see IsTouched), or the data leave one of its
  // directions free (CheckDetermined; the message names the directions and
  // the variables they are tied to). A variable the data determine keeps its
  // covariance when others are free: the block of (JᵀJ)⁺, which no choice of
  // the free directions changes.
  Eigen::MatrixXd Covariance(int id);
  // Joint covariance of several distinct variables, blocks in the order
  // given; throws as Covariance, naming the variables at fault.
  Eigen::MatrixXd JointCovariance(const std::vector<int>& ids);

 private:
  struct Variable;
  struct Measurement;
  class HookDispatcher;
  class Busy;
  void CheckVariable(int id) const;
  void CheckMeasurement(int id) const;
  void StoreValue(int id, const double* ambient, const char* what);
  SolveSummary SolveByLineSearch(const SolverOptions& options);
  std::string FirstNonFiniteMeasurement();
  // The Ceres problem with every variable and measurement added so far.
  ceres::Problem* CeresProblem();

  // Bumped whenever values, fixed flags, variables or measurements change;
  // the cached determinedness is valid for one generation.
  long long generation_ = 0;
  long long determinedness_generation_ = -1;
  DeterminednessOptions determinedness_options_;
  Determinedness determinedness_;
  // CheckDetermined and EvaluateSparseJacobian without taking Busy (for
  // callers that hold it).
  const Determinedness& Determine(const DeterminednessOptions& options);
  SparseJacobianEvaluation SparseJacobian();
  std::string DescribeUndetermined(const Determinedness& d) const;

  // The thread running Solve or an evaluation through Ceres (none when idle).
  mutable std::atomic<std::thread::id> busy_{};
  // Σ over measurements of their Jacobian entries (Ceres indexes them with int).
  long long jacobian_entries_ = 0;
  std::unique_ptr<HookDispatcher> hooks_;
  MeasurementNamer namer_;
  std::unique_ptr<ceres::Problem> problem_;
  // How many variables and measurements problem_ holds (the first ones).
  int ceres_vars_ = 0;
  int ceres_meas_ = 0;
  std::vector<std::unique_ptr<Variable>> vars_;
  std::vector<Measurement> meas_;
};

}  // namespace boxplus
