#include "boxplus/problem.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include <ceres/covariance.h>
#include <ceres/evaluation_callback.h>
#include <ceres/iteration_callback.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "boxplus/errors.h"
#include "boxplus/progress.h"
#include "solver/gauss_newton_line_search.h"

namespace boxplus {

struct Problem::Variable {
  std::shared_ptr<const ceres::Manifold> manifold;
  std::unique_ptr<double[]> data;  // stable address: Ceres keeps the pointer
  std::string name;
  bool fixed = false;
};

struct Problem::Measurement {
  std::shared_ptr<ceres::CostFunction> cost;
  std::shared_ptr<ceres::LossFunction> loss;
  std::vector<int> vars;
  NoiseModel noise;
  std::string name;
  ceres::ResidualBlockId block = nullptr;
};

// Ceres accepts one EvaluationCallback per problem; this one fans out.
class Problem::HookDispatcher final : public ceres::EvaluationCallback {
 public:
  void PrepareForEvaluation(bool evaluate_jacobians,
                            bool new_evaluation_point) override {
    for (auto& hook : hooks) hook(evaluate_jacobians, new_evaluation_point);
  }
  std::vector<EvaluationHook> hooks;
};

namespace {

ceres::Problem::Options NonOwningOptions(ceres::EvaluationCallback* callback) {
  ceres::Problem::Options o;
  o.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.evaluation_callback = callback;
  // Removing residual blocks is rare; skip the bookkeeping that makes it fast.
  o.enable_fast_removal = false;
  return o;
}

class CallbackAdapter final : public ceres::IterationCallback {
 public:
  CallbackAdapter(const SolverOptions& options, bool* interrupted,
                  std::function<void()> on_accepted)
      : options_(options), interrupted_(interrupted), on_accepted_(std::move(on_accepted)) {}
  ceres::CallbackReturnType operator()(
      const ceres::IterationSummary& s) override {
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

}  // namespace

Problem::Problem()
    : hooks_(std::make_unique<HookDispatcher>()),
      problem_(std::make_unique<ceres::Problem>(NonOwningOptions(hooks_.get()))) {}

Problem::~Problem() = default;

void Problem::CheckVariable(int id) const {
  BOXPLUS_CHECK_INDEX(id >= 0 && id < num_variables(), "unknown variable id ",
                      id, " (the problem has ", num_variables(), " variables)");
}

void Problem::CheckMeasurement(int id) const {
  BOXPLUS_CHECK_INDEX(id >= 0 && id < num_measurements(),
                      "unknown measurement id ", id, " (the problem has ",
                      num_measurements(), " measurements)");
}

int Problem::AddVariable(std::shared_ptr<const ceres::Manifold> manifold,
                         const double* init, const std::string& name) {
  BOXPLUS_CHECK(manifold != nullptr, "variable '", name, "': no manifold");
  const int id = num_variables();
  auto v = std::make_unique<Variable>();
  const int n = manifold->AmbientSize();
  v->data.reset(new double[n]);
  for (int i = 0; i < n; ++i) {
    BOXPLUS_CHECK(std::isfinite(init[i]), "variable ",
                  name.empty() ? std::to_string(id) : "'" + name + "'",
                  ": initial value has a non-finite entry");
    v->data[i] = init[i];
  }
  v->manifold = std::move(manifold);
  v->name = name.empty() ? "x" + std::to_string(id) : name;
  problem_->AddParameterBlock(v->data.get(), n,
                              const_cast<ceres::Manifold*>(v->manifold.get()));
  vars_.push_back(std::move(v));
  return id;
}

const std::string& Problem::variable_name(int id) const {
  CheckVariable(id);
  return vars_[id]->name;
}
const ceres::Manifold& Problem::manifold(int id) const {
  CheckVariable(id);
  return *vars_[id]->manifold;
}
const double* Problem::value(int id) const {
  CheckVariable(id);
  return vars_[id]->data.get();
}
void Problem::SetValue(int id, const double* ambient) {
  CheckVariable(id);
  const int n = vars_[id]->manifold->AmbientSize();
  for (int i = 0; i < n; ++i) {
    BOXPLUS_CHECK(std::isfinite(ambient[i]), "variable '", vars_[id]->name,
                  "': value has a non-finite entry");
  }
  std::copy(ambient, ambient + n, vars_[id]->data.get());
}
void Problem::SetFixed(int id, bool fixed) {
  CheckVariable(id);
  vars_[id]->fixed = fixed;
  if (fixed) {
    problem_->SetParameterBlockConstant(vars_[id]->data.get());
  } else {
    problem_->SetParameterBlockVariable(vars_[id]->data.get());
  }
}
bool Problem::IsFixed(int id) const {
  CheckVariable(id);
  return vars_[id]->fixed;
}

int Problem::AddMeasurement(std::shared_ptr<ceres::CostFunction> cost,
                            const std::vector<int>& var_ids, const NoiseModel& noise,
                            std::shared_ptr<ceres::LossFunction> loss,
                            const std::string& name) {
  const int id = num_measurements();
  const std::string what =
      "measurement " + (name.empty() ? std::to_string(id) : "'" + name + "'");
  BOXPLUS_CHECK(cost != nullptr, what, ": no cost function");
  const auto& sizes = cost->parameter_block_sizes();
  BOXPLUS_CHECK(sizes.size() == var_ids.size(), what, ": its function takes ",
                sizes.size(), " variables but ", var_ids.size(),
                " were given");
  BOXPLUS_CHECK(cost->num_residuals() > 0, what, ": has no residuals");
  BOXPLUS_CHECK(noise.dim() == 0 || cost->num_residuals() % noise.dim() == 0, what,
                ": noise of dimension ", noise.dim(), " for ", cost->num_residuals(),
                " residuals");
  std::vector<double*> blocks;
  std::set<int> seen;
  for (size_t k = 0; k < var_ids.size(); ++k) {
    const int v = var_ids[k];
    BOXPLUS_CHECK_INDEX(v >= 0 && v < num_variables(), what,
                        ": unknown variable id ", v, " (argument ", k, ")");
    BOXPLUS_CHECK(seen.insert(v).second, what, ": variable '", vars_[v]->name,
                  "' is listed twice");
    BOXPLUS_CHECK(sizes[k] == vars_[v]->manifold->AmbientSize(), what,
                  ": argument ", k, " expects ", sizes[k],
                  " ambient coordinates but variable '", vars_[v]->name,
                  "' has ", vars_[v]->manifold->AmbientSize());
    blocks.push_back(vars_[v]->data.get());
  }
  Measurement m;
  m.cost = std::move(cost);
  m.loss = std::move(loss);
  m.vars = var_ids;
  m.noise = noise;
  m.name = name.empty() ? "z" + std::to_string(id) : name;
  m.block = problem_->AddResidualBlock(m.cost.get(), m.loss.get(), blocks);
  meas_.push_back(std::move(m));
  return id;
}

int Problem::num_measurements() const { return static_cast<int>(meas_.size()); }

const std::string& Problem::measurement_name(int id) const {
  CheckMeasurement(id);
  return meas_[id].name;
}
const std::vector<int>& Problem::measurement_variables(int id) const {
  CheckMeasurement(id);
  return meas_[id].vars;
}
int Problem::residual_size(int id) const {
  CheckMeasurement(id);
  return meas_[id].cost->num_residuals();
}

const NoiseModel& Problem::noise(int id) const {
  CheckMeasurement(id);
  return meas_[id].noise;
}

void Problem::AddEvaluationHook(EvaluationHook hook) {
  hooks_->hooks.push_back(std::move(hook));
}

SolveSummary Problem::Solve(const SolverOptions& options) {
  Validate(options);
  SolveSummary out;
  if (num_measurements() == 0) {
    out.termination = "convergence";
    out.message = "no measurements";
    out.usable = true;
    return out;
  }
  if (options.method == Method::kGaussNewtonLineSearch) return SolveByLineSearch(options);
  ceres::Solver::Options o;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  BOXPLUS_CHECK(options.initial_trust_region_radius > 0,
                "initial_trust_region_radius must be > 0");
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
      break;  // solved by SolveByLineSearch
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
  bool interrupted = false;
  // The last accepted point: restored when the solve fails part-way (an
  // evaluation error, Ctrl-C inside a measurement function), so the variables
  // never hold a rejected trial point.
  std::vector<std::vector<double>> best(vars_.size());
  auto snapshot = [this, &best] {
    for (size_t i = 0; i < vars_.size(); ++i) {
      const double* d = vars_[i]->data.get();
      best[i].assign(d, d + vars_[i]->manifold->AmbientSize());
    }
  };
  snapshot();
  CallbackAdapter callback(options, &interrupted, snapshot);
  o.callbacks.push_back(&callback);
  o.update_state_every_iteration = true;
  std::string why;
  BOXPLUS_CHECK(o.IsValid(&why), "invalid solver options: ", why);

  ceres::Solver::Summary s;
  ceres::Solve(o, problem_.get(), &s);
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
  if (interrupted || s.termination_type == ceres::FAILURE) {
    for (size_t i = 0; i < vars_.size(); ++i) {
      std::copy(best[i].begin(), best[i].end(), vars_[i]->data.get());
    }
    out.final_cost = std::min(out.final_cost, out.initial_cost);
  }
  return out;
}

SolveSummary Problem::SolveByLineSearch(const SolverOptions& options) {
  std::vector<internal::LsqBlock> blocks;
  blocks.reserve(vars_.size());
  for (const auto& v : vars_) blocks.push_back({v->data.get(), v->manifold.get(), v->fixed});
  std::vector<internal::LsqTerm> terms;
  terms.reserve(meas_.size());
  for (const Measurement& m : meas_) terms.push_back({m.cost.get(), m.loss.get(), m.vars});
  return internal::SolveGaussNewtonLineSearch(
      blocks, terms, options,
      [this](bool jacobians) { hooks_->PrepareForEvaluation(jacobians, true); });
}

Eigen::VectorXd Problem::Residual(int measurement_id) {
  CheckMeasurement(measurement_id);
  const Measurement& m = meas_[measurement_id];
  std::vector<const double*> blocks;
  for (int v : m.vars) blocks.push_back(vars_[v]->data.get());
  hooks_->PrepareForEvaluation(false, true);
  Eigen::VectorXd r(m.cost->num_residuals());
  BOXPLUS_CHECK(m.cost->Evaluate(blocks.data(), r.data(), nullptr),
                "measurement '", m.name, "': evaluation failed");
  return r;
}

Eigen::VectorXd Problem::Error(int measurement_id) {
  Eigen::VectorXd r = Residual(measurement_id);
  const NoiseModel& noise = meas_[measurement_id].noise;
  return noise.dim() == 0 ? r : noise.Unwhiten(r);
}

double Problem::Cost() {
  double cost = 0.0;
  ceres::Problem::EvaluateOptions eo;
  BOXPLUS_CHECK(problem_->Evaluate(eo, &cost, nullptr, nullptr, nullptr),
                "evaluating the cost failed");
  return cost;
}

JacobianEvaluation Problem::EvaluateJacobian() {
  JacobianEvaluation out;
  ceres::Problem::EvaluateOptions eo;
  int cols = 0;
  for (int v = 0; v < num_variables(); ++v) {
    if (vars_[v]->fixed) continue;
    out.variables.push_back(v);
    out.column_offsets.push_back(cols);
    cols += vars_[v]->manifold->TangentSize();
    eo.parameter_blocks.push_back(vars_[v]->data.get());
  }
  int rows = 0;
  for (const Measurement& m : meas_) {
    out.row_offsets.push_back(rows);
    rows += m.cost->num_residuals();
    eo.residual_blocks.push_back(m.block);
  }
  out.residuals.setZero(rows);
  out.jacobian.setZero(rows, cols);
  if (rows == 0 || cols == 0) return out;
  double cost = 0.0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  BOXPLUS_CHECK(problem_->Evaluate(eo, &cost, &residuals, nullptr, &crs),
                "evaluating the Jacobian failed");
  BOXPLUS_CHECK(crs.num_rows == rows && crs.num_cols == cols,
                "Jacobian has an unexpected shape");
  out.residuals = Eigen::Map<Eigen::VectorXd>(residuals.data(), rows);
  for (int r = 0; r < rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      out.jacobian(r, crs.cols[k]) = crs.values[k];
    }
  }
  return out;
}

Eigen::MatrixXd Problem::Covariance(int id) { return JointCovariance({id}); }

Eigen::MatrixXd Problem::JointCovariance(const std::vector<int>& ids) {
  std::vector<int> offsets;
  int total = 0;
  for (int id : ids) {
    CheckVariable(id);
    BOXPLUS_CHECK(!vars_[id]->fixed, "variable '", vars_[id]->name,
                  "' is fixed: it has no covariance");
    offsets.push_back(total);
    total += vars_[id]->manifold->TangentSize();
  }
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::SPARSE_QR;
  co.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (size_t i = 0; i < ids.size(); ++i) {
    for (size_t j = i; j < ids.size(); ++j) {
      pairs.emplace_back(vars_[ids[i]]->data.get(), vars_[ids[j]]->data.get());
    }
  }
  std::string names;
  for (int id : ids) names += (names.empty() ? "'" : ", '") + vars_[id]->name + "'";
  BOXPLUS_CHECK(cov.Compute(pairs, problem_.get()),
                "covariance of ", names,
                " is undefined: the measurements do not determine every "
                "parameter (rank-deficient Jacobian)");
  Eigen::MatrixXd out(total, total);
  using RowMajor =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (size_t i = 0; i < ids.size(); ++i) {
    for (size_t j = i; j < ids.size(); ++j) {
      const int ni = vars_[ids[i]]->manifold->TangentSize();
      const int nj = vars_[ids[j]]->manifold->TangentSize();
      RowMajor block(ni, nj);
      cov.GetCovarianceBlockInTangentSpace(vars_[ids[i]]->data.get(),
                                           vars_[ids[j]]->data.get(),
                                           block.data());
      out.block(offsets[i], offsets[j], ni, nj) = block;
      out.block(offsets[j], offsets[i], nj, ni) = block.transpose();
    }
  }
  return out;
}

}  // namespace boxplus
