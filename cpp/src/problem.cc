#include "boxplus/problem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <ceres/covariance.h>
#include <ceres/crs_matrix.h>
#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>

#include "boxplus/errors.h"
#include "manifold_domain.h"
#include "solver/ceres_trust_region.h"
#include "solver/gauss_newton_line_search.h"
#include "solver/gauss_newton_with_fallback.h"

namespace boxplus {

struct Problem::Variable {
  std::shared_ptr<const ceres::Manifold> manifold;
  std::unique_ptr<double[]> data;  // stable address: Ceres keeps the pointer
  std::string name;
  bool fixed = false;
  bool euclidean = false;  // Ceres gets no manifold (x ⊞ δ = x + δ)
  int num_measurements = 0;
  std::vector<std::string> labels;  // of the tangent directions; may be empty
};

struct Problem::Measurement {
  std::shared_ptr<ceres::CostFunction> cost;
  std::shared_ptr<ceres::LossFunction> loss;
  std::vector<int> vars;
  NoiseModel noise;
  std::string name;  // empty: named by the namer or "z<id>" (measurement_name)
  ceres::ResidualBlockId block = nullptr;
};

// Ceres accepts one EvaluationCallback per problem; this one fans out.
class Problem::HookDispatcher final : public ceres::EvaluationCallback {
 public:
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override {
    for (auto& hook : hooks) hook(evaluate_jacobians, new_evaluation_point);
  }
  std::vector<EvaluationHook> hooks;
};

namespace {

// "measurement 12" or "variable 'name'" in a message, formatted only when a
// message is written (a pose graph adds 10⁵–10⁶ variables and measurements,
// and most of their set-up time was allocation).
struct What {
  const char* kind;  // "measurement", "variable"
  int id;
  const std::string& name;
};

std::ostream& operator<<(std::ostream& out, const What& w) {
  if (w.name.empty()) return out << w.kind << " " << w.id;
  return out << w.kind << " '" << w.name << "'";
}

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

// Ceres indexes parameter blocks, Jacobians and JᵀJ with int.
constexpr long long kCeresMaxEntries = std::numeric_limits<int>::max();

}  // namespace

// Holds the problem for one thread during Solve or an evaluation: a call from
// another thread meanwhile throws instead of racing on Ceres' state (and on
// the evaluation hooks' caches). `reentrant` calls (residuals of single
// measurements) are allowed from the solving thread itself, e.g. from an
// iteration callback.
class Problem::Busy {
 public:
  Busy(const Problem& p, const char* what, bool reentrant = false) : p_(p) {
    const std::thread::id me = std::this_thread::get_id();
    std::thread::id owner{};
    if (p_.busy_.compare_exchange_strong(owner, me)) return;
    if (owner == me && reentrant) {
      held_ = false;
      return;
    }
    BOXPLUS_CHECK(owner != me, what,
                  ": not allowed while the problem is being solved "
                  "(from an iteration callback or an evaluation hook)");
    throw ::boxplus::Error(std::string(what) +
                           ": problem is already being solved in another thread");
  }
  ~Busy() {
    if (held_) p_.busy_.store(std::thread::id{});
  }
  Busy(const Busy&) = delete;
  Busy& operator=(const Busy&) = delete;

 private:
  const Problem& p_;
  bool held_ = true;
};

Problem::Problem()
    : hooks_(std::make_unique<HookDispatcher>()),
      problem_(std::make_unique<ceres::Problem>(NonOwningOptions(hooks_.get()))) {}

Problem::~Problem() = default;

void Problem::CheckVariable(int id) const {
  BOXPLUS_CHECK_INDEX(id >= 0 && id < num_variables(), "unknown variable id ", id,
                      " (the problem has ", num_variables(), " variables)");
}

void Problem::CheckMeasurement(int id) const {
  BOXPLUS_CHECK_INDEX(id >= 0 && id < num_measurements(), "unknown measurement id ", id,
                      " (the problem has ", num_measurements(), " measurements)");
}

int Problem::AddVariable(std::shared_ptr<const ceres::Manifold> manifold, const double* init,
                         const std::string& name) {
  const Busy busy(*this, "AddVariable");
  const int id = num_variables();
  const What what{"variable", id, name};
  BOXPLUS_CHECK(manifold != nullptr, what, ": no manifold");
  const int n = manifold->AmbientSize();
  const int t = manifold->TangentSize();
  BOXPLUS_CHECK(n >= 1 && t >= 0 && t <= n, what, ": manifold of ambient size ", n,
                " and tangent size ", t, " (need 0 <= tangent <= ambient, ambient >= 1)");
  auto v = std::make_unique<Variable>();
  v->euclidean = internal::IsEuclidean(*manifold);
  // Ceres stores an ambient × tangent Plus Jacobian for every manifold.
  BOXPLUS_CHECK(v->euclidean || static_cast<long long>(n) * t <= kCeresMaxEntries, what, ": its ",
                n, " x ", t, " Plus Jacobian has more entries than Ceres can index");
  v->data.reset(new double[n]);
  v->manifold = std::move(manifold);
  v->name = name.empty() ? "x" + std::to_string(id) : name;
  vars_.push_back(std::move(v));
  try {
    StoreValue(id, init, "initial value");
  } catch (...) {
    vars_.pop_back();  // validate before the problem changes
    throw;
  }
  return id;
}

// Ceres' blocks are added on the first use of its problem, not by
// AddVariable/AddMeasurement: the line-search solver never uses them, and on
// a pose graph they were about 40 % of the build time and most of the
// teardown. Variables first, then measurements, each in id order: the same
// problem Ceres would hold had they been added one by one.
ceres::Problem* Problem::CeresProblem() {
  for (; ceres_vars_ < num_variables(); ++ceres_vars_) {
    Variable& var = *vars_[ceres_vars_];
    problem_->AddParameterBlock(
        var.data.get(), var.manifold->AmbientSize(),
        var.euclidean ? nullptr : const_cast<ceres::Manifold*>(var.manifold.get()));
    if (var.fixed) problem_->SetParameterBlockConstant(var.data.get());
  }
  std::vector<double*> blocks;
  for (; ceres_meas_ < num_measurements(); ++ceres_meas_) {
    Measurement& m = meas_[ceres_meas_];
    blocks.clear();
    for (int v : m.vars) blocks.push_back(vars_[v]->data.get());
    m.block = problem_->AddResidualBlock(m.cost.get(), m.loss.get(), blocks);
  }
  return problem_.get();
}

// Copies a finite ambient value into the variable's storage, its unit parts
// normalised.
void Problem::StoreValue(int id, const double* ambient, const char* what) {
  Variable& v = *vars_[id];
  const int n = v.manifold->AmbientSize();
  // Checked and normalised in a copy: a refused value leaves the old one.
  constexpr int kSmall = 16;
  double small[kSmall];
  std::vector<double> large;
  double* x = small;
  if (n > kSmall) {
    large.resize(n);
    x = large.data();
  }
  std::copy(ambient, ambient + n, x);
  for (int i = 0; i < n; ++i) {
    BOXPLUS_CHECK(std::isfinite(x[i]), "variable '", v.name, "': ", what,
                  " has a non-finite entry (", i, ")");
  }
  internal::NormaliseAmbient(*v.manifold, x, [&v] { return "variable '" + v.name + "'"; });
  std::copy(x, x + n, v.data.get());
  ++generation_;
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
  const Busy busy(*this, "SetValue");
  CheckVariable(id);
  StoreValue(id, ambient, "value");
}
void Problem::SetFixed(int id, bool fixed) {
  const Busy busy(*this, "SetFixed");
  CheckVariable(id);
  vars_[id]->fixed = fixed;
  ++generation_;
  if (id >= ceres_vars_) return;  // CeresProblem() applies it when it adds the block
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
bool Problem::IsTouched(int id) const {
  CheckVariable(id);
  return vars_[id]->num_measurements > 0;
}

void Problem::Reserve(int variables, int measurements) {
  vars_.reserve(std::max(0, variables));
  meas_.reserve(std::max(0, measurements));
}

int Problem::AddMeasurement(std::shared_ptr<ceres::CostFunction> cost, std::vector<int> var_ids,
                            NoiseModel noise, std::shared_ptr<ceres::LossFunction> loss,
                            const std::string& name) {
  const Busy busy(*this, "AddMeasurement");
  const int id = num_measurements();
  const What what{"measurement", id, name};
  BOXPLUS_CHECK(cost != nullptr, what, ": no cost function");
  BOXPLUS_CHECK(!var_ids.empty(), what, ": depends on no variable");
  const auto& sizes = cost->parameter_block_sizes();
  BOXPLUS_CHECK(sizes.size() == var_ids.size(), what, ": its function takes ", sizes.size(),
                " variables but ", var_ids.size(), " were given");
  BOXPLUS_CHECK(cost->num_residuals() > 0, what, ": has no residuals");
  BOXPLUS_CHECK(noise.dim() == 0 || cost->num_residuals() % noise.dim() == 0, what,
                ": noise of dimension ", noise.dim(), " for ", cost->num_residuals(), " residuals");
  for (size_t k = 0; k < var_ids.size(); ++k) {
    const int v = var_ids[k];
    BOXPLUS_CHECK_INDEX(v >= 0 && v < num_variables(), what, ": unknown variable id ", v,
                        " (argument ", k, ")");
    BOXPLUS_CHECK(std::find(var_ids.begin(), var_ids.begin() + k, v) == var_ids.begin() + k, what,
                  ": variable '", vars_[v]->name, "' is listed twice");
    BOXPLUS_CHECK(sizes[k] == vars_[v]->manifold->AmbientSize(), what, ": argument ", k,
                  " expects ", sizes[k], " ambient coordinates but variable '", vars_[v]->name,
                  "' has ", vars_[v]->manifold->AmbientSize());
  }
  // Ceres' evaluation buffers hold nr × ambient per block, its Jacobian
  // nr × tangent per block summed over the problem, JᵀJ a dense
  // tangent × tangent block per measurement; all int-indexed.
  const long long nr = cost->num_residuals();
  long long ambient = 0, tangent = 0;
  for (int v : var_ids) {
    ambient += vars_[v]->manifold->AmbientSize();
    tangent += vars_[v]->manifold->TangentSize();
  }
  BOXPLUS_CHECK(
      nr * ambient <= kCeresMaxEntries && jacobian_entries_ + nr * tangent <= kCeresMaxEntries,
      what, ": its Jacobian (", nr, " residuals x ", ambient,
      " coordinates) takes the problem past the ", kCeresMaxEntries,
      " Jacobian entries Ceres can index");
  BOXPLUS_CHECK(tangent * tangent <= kCeresMaxEntries, what,
                ": its block of the normal "
                "equations (",
                tangent, " x ", tangent, " tangent coordinates) has more than the ",
                kCeresMaxEntries, " entries Ceres can index");
  jacobian_entries_ += nr * tangent;
  for (int v : var_ids) ++vars_[v]->num_measurements;
  Measurement m;
  m.cost = std::move(cost);
  m.loss = std::move(loss);
  m.vars = std::move(var_ids);
  m.noise = std::move(noise);
  m.name = name;
  meas_.push_back(std::move(m));
  ++generation_;
  return id;
}

int Problem::num_measurements() const { return static_cast<int>(meas_.size()); }

std::string Problem::measurement_name(int id) const {
  CheckMeasurement(id);
  if (!meas_[id].name.empty()) return meas_[id].name;
  if (namer_) {
    std::string name = namer_(id);
    if (!name.empty()) return name;
  }
  return "z" + std::to_string(id);
}

void Problem::SetMeasurementNamer(MeasurementNamer namer) { namer_ = std::move(namer); }
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
  const Busy busy(*this, "AddEvaluationHook");
  hooks_->hooks.push_back(std::move(hook));
}

SolveSummary Problem::Solve(const SolverOptions& options) {
  const Busy busy(*this, "Solve");
  Validate(options);
  ++generation_;  // the solvers write the values in place
  SolveSummary out;
  if (num_measurements() == 0) {
    out.termination = "convergence";
    out.message = "no measurements";
    out.usable = true;
    return out;
  }
  auto trust_region = [this](const SolverOptions& o) {
    std::vector<internal::LsqBlock> blocks;
    for (const auto& v : vars_) blocks.push_back({v->data.get(), v->manifold.get(), v->fixed});
    return internal::SolveTrustRegion(CeresProblem(), blocks, o);
  };
  if (options.method == Method::kGaussNewtonLineSearch) {
    out = SolveByLineSearch(options);
  } else if (options.method == Method::kGaussNewtonFallback) {
    out = internal::SolveGaussNewtonWithFallback(
        options, [this](const SolverOptions& o) { return SolveByLineSearch(o); }, trust_region);
  } else {
    out = trust_region(options);
  }
  // The summary describes the values returned: the solvers report the cost of
  // their last accepted step, which the stored values can differ from in the
  // last digits (unit parts renormalised, an interrupted step) and, for extreme
  // inputs, by more; one more evaluation settles it.
  if (std::isfinite(out.final_cost)) {
    double cost = 0.0;
    ceres::Problem::EvaluateOptions eo;
    if (CeresProblem()->Evaluate(eo, &cost, nullptr, nullptr, nullptr)) out.final_cost = cost;
  }
  // Ceres' LM "converges" from an infinite cost (residuals too large to
  // square) to an infinite cost; say which measurement is at fault.
  std::string why;
  if (!std::isfinite(out.initial_cost) || (out.termination == "failure" && out.iterations <= 0)) {
    why = FirstNonFiniteMeasurement();
    if (!why.empty()) {
      why = "at the start, " + why;
    } else if (!std::isfinite(out.initial_cost)) {
      why = "the cost is not finite at the start";
    }
  } else if (!std::isfinite(out.final_cost)) {
    why = "the cost is not finite at the end";
  }
  if (!why.empty()) {
    out.message = why + " (" + out.message + ")";
    out.termination = "failure";
    out.usable = false;
  }
  return out;
}

SolveSummary Problem::SolveByLineSearch(const SolverOptions& options) {
  std::vector<internal::LsqBlock> blocks;
  blocks.reserve(vars_.size());
  for (const auto& v : vars_) {
    blocks.push_back({v->data.get(), v->manifold.get(), v->fixed, v->euclidean});
  }
  std::vector<internal::LsqTerm> terms;
  terms.reserve(meas_.size());
  for (const Measurement& m : meas_) terms.push_back({m.cost.get(), m.loss.get(), m.vars});
  return internal::SolveGaussNewtonLineSearch(blocks, terms, options, [this](bool jacobians) {
    hooks_->PrepareForEvaluation(jacobians, true);
  });
}

// Names the first measurement whose residual cannot be evaluated, is not
// finite or overflows when squared at the current values; "" when there is
// none. Diagnostics after a failure: errors thrown here are not the answer.
std::string Problem::FirstNonFiniteMeasurement() {
  try {
    hooks_->PrepareForEvaluation(false, true);
    for (int id = 0; id < num_measurements(); ++id) {
      const Measurement& m = meas_[id];
      std::vector<const double*> blocks;
      for (int v : m.vars) blocks.push_back(vars_[v]->data.get());
      Eigen::VectorXd r(m.cost->num_residuals());
      const std::string what = "measurement '" + measurement_name(id) + "'";
      if (!m.cost->Evaluate(blocks.data(), r.data(), nullptr)) return what + " cannot be evaluated";
      if (!r.allFinite()) return what + " has a non-finite residual";
      if (!std::isfinite(r.squaredNorm())) return what + " has a residual whose square overflows";
    }
  } catch (const std::exception& e) {
    return std::string("evaluating the measurements failed: ") + e.what();
  }
  return "";
}

Eigen::VectorXd Problem::Residual(int measurement_id) {
  const Busy busy(*this, "Residual", /*reentrant=*/true);
  CheckMeasurement(measurement_id);
  const Measurement& m = meas_[measurement_id];
  std::vector<const double*> blocks;
  for (int v : m.vars) blocks.push_back(vars_[v]->data.get());
  hooks_->PrepareForEvaluation(false, true);
  Eigen::VectorXd r(m.cost->num_residuals());
  BOXPLUS_CHECK(m.cost->Evaluate(blocks.data(), r.data(), nullptr), "measurement '",
                measurement_name(measurement_id), "': evaluation failed");
  return r;
}

Eigen::VectorXd Problem::Error(int measurement_id) {
  Eigen::VectorXd r = Residual(measurement_id);
  const NoiseModel& noise = meas_[measurement_id].noise;
  return noise.dim() == 0 ? r : noise.Unwhiten(r);
}

Eigen::VectorXd Problem::Errors(const std::vector<int>& measurement_ids, bool whitened) {
  const Busy busy(*this, "Errors", /*reentrant=*/true);
  Eigen::Index size = 0;
  for (int id : measurement_ids) {
    CheckMeasurement(id);
    size += meas_[id].cost->num_residuals();
  }
  Eigen::VectorXd out(size);
  if (measurement_ids.empty()) return out;
  hooks_->PrepareForEvaluation(false, true);
  std::vector<const double*> blocks;
  Eigen::Index at = 0;
  for (int id : measurement_ids) {
    const Measurement& m = meas_[id];
    const int n = m.cost->num_residuals();
    blocks.clear();
    for (int v : m.vars) blocks.push_back(vars_[v]->data.get());
    BOXPLUS_CHECK(m.cost->Evaluate(blocks.data(), out.data() + at, nullptr), "measurement '",
                  measurement_name(id), "': evaluation failed");
    if (!whitened && m.noise.dim() != 0) {
      out.segment(at, n) = m.noise.Unwhiten(out.segment(at, n));
    }
    at += n;
  }
  return out;
}

double Problem::Cost() {
  const Busy busy(*this, "Cost");
  double cost = 0.0;
  ceres::Problem::EvaluateOptions eo;
  if (!CeresProblem()->Evaluate(eo, &cost, nullptr, nullptr, nullptr)) {
    throw ::boxplus::Error("evaluating the cost failed; " + FirstNonFiniteMeasurement());
  }
  return cost;
}

JacobianEvaluation Problem::EvaluateJacobian() {
  const Busy busy(*this, "EvaluateJacobian");
  SparseJacobianEvaluation sparse = SparseJacobian();
  JacobianEvaluation out;
  out.residuals = std::move(sparse.residuals);
  out.jacobian = Eigen::MatrixXd(sparse.jacobian);
  out.variables = std::move(sparse.variables);
  out.column_offsets = std::move(sparse.column_offsets);
  int rows = 0;
  for (const Measurement& m : meas_) {
    out.row_offsets.push_back(rows);
    rows += m.cost->num_residuals();
  }
  return out;
}

SparseJacobianEvaluation Problem::EvaluateSparseJacobian() {
  const Busy busy(*this, "EvaluateSparseJacobian");
  return SparseJacobian();
}

SparseJacobianEvaluation Problem::SparseJacobian() {
  SparseJacobianEvaluation out;
  int cols = 0;
  for (int v = 0; v < num_variables(); ++v) {
    if (vars_[v]->fixed) continue;
    out.variables.push_back(v);
    out.column_offsets.push_back(cols);
    cols += vars_[v]->manifold->TangentSize();
  }
  int rows = 0;
  for (const Measurement& m : meas_) rows += m.cost->num_residuals();
  out.jacobian.resize(rows, cols);
  out.residuals.setZero(rows);
  if (rows == 0 || cols == 0) return out;
  // Without robust losses, from the cost functions directly: Ceres'
  // Evaluate builds a program and an evaluator for each call (18 ms for the
  // Jacobian of parking-garage's 6275 edges).
  bool plain = true;
  for (const Measurement& m : meas_) plain = plain && !m.loss;
  if (plain) {
    std::vector<int> column(vars_.size(), -1);
    for (size_t q = 0; q < out.variables.size(); ++q)
      column[out.variables[q]] = out.column_offsets[q];
    hooks_->PrepareForEvaluation(true, true);
    // Each free variable's Plus Jacobian (ambient × tangent) at its value.
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> plus(
        vars_.size());
    for (int v : out.variables) {
      const Variable& var = *vars_[v];
      if (var.euclidean) continue;
      plus[v].resize(var.manifold->AmbientSize(), var.manifold->TangentSize());
      if (!var.manifold->PlusJacobian(var.data.get(), plus[v].data())) {
        throw ::boxplus::Error("evaluating the Jacobian failed: the Plus Jacobian of variable '" +
                               var.name + "'");
      }
    }
    std::vector<Eigen::Triplet<double>> entries;
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> ambient;
    std::vector<const double*> values;
    std::vector<double*> pointers;
    int row = 0;
    for (size_t id = 0; id < meas_.size(); ++id) {
      const Measurement& m = meas_[id];
      const int d = m.cost->num_residuals();
      const std::vector<int32_t>& sizes = m.cost->parameter_block_sizes();
      values.clear();
      pointers.clear();
      ambient.resize(m.vars.size());
      for (size_t b = 0; b < m.vars.size(); ++b) {
        values.push_back(vars_[m.vars[b]]->data.get());
        ambient[b].resize(d, sizes[b]);
        pointers.push_back(column[m.vars[b]] >= 0 ? ambient[b].data() : nullptr);
      }
      if (!m.cost->Evaluate(values.data(), out.residuals.data() + row, pointers.data()) ||
          !out.residuals.segment(row, d).allFinite()) {
        throw ::boxplus::Error("evaluating the Jacobian failed; " + FirstNonFiniteMeasurement());
      }
      for (size_t b = 0; b < m.vars.size(); ++b) {
        const int v = m.vars[b], c0 = column[v];
        if (c0 < 0) continue;
        const Eigen::MatrixXd J = vars_[v]->euclidean ? Eigen::MatrixXd(ambient[b])
                                                      : Eigen::MatrixXd(ambient[b] * plus[v]);
        for (int i = 0; i < J.rows(); ++i) {
          for (int j = 0; j < J.cols(); ++j) {
            if (J(i, j) != 0.0) entries.emplace_back(row + i, c0 + j, J(i, j));
          }
        }
      }
      row += d;
    }
    out.jacobian.setFromTriplets(entries.begin(), entries.end());
    return out;
  }
  // With a robust loss, Ceres' Evaluate applies its correction.
  ceres::Problem* ceres = CeresProblem();
  ceres::Problem::EvaluateOptions eo;
  for (int v : out.variables) eo.parameter_blocks.push_back(vars_[v]->data.get());
  for (const Measurement& m : meas_) eo.residual_blocks.push_back(m.block);
  double cost = 0.0;
  ceres::CRSMatrix crs;
  std::vector<double> residuals;
  if (!ceres->Evaluate(eo, &cost, &residuals, nullptr, &crs)) {
    throw ::boxplus::Error("evaluating the Jacobian failed; " + FirstNonFiniteMeasurement());
  }
  BOXPLUS_CHECK(crs.num_rows == rows && crs.num_cols == cols, "Jacobian has an unexpected shape");
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(crs.values.size());
  for (int r = 0; r < rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      entries.emplace_back(r, crs.cols[k], crs.values[k]);
    }
  }
  out.jacobian.setFromTriplets(entries.begin(), entries.end());
  out.residuals = Eigen::Map<Eigen::VectorXd>(residuals.data(), rows);
  return out;
}

const Determinedness& Problem::CheckDetermined(const DeterminednessOptions& options) {
  const Busy busy(*this, "CheckDetermined");
  return Determine(options);
}

const Determinedness& Problem::Determine(const DeterminednessOptions& options) {
  if (determinedness_generation_ == generation_ &&
      determinedness_options_.relative_tolerance == options.relative_tolerance &&
      determinedness_options_.support_tolerance == options.support_tolerance) {
    return determinedness_;
  }
  SparseJacobianEvaluation j = SparseJacobian();
  determinedness_ = AnalyseDeterminedness(j.jacobian, j.variables, j.column_offsets, options);
  determinedness_options_ = options;
  determinedness_generation_ = generation_;
  return determinedness_;
}

std::string Problem::DescribeUndetermined(const Determinedness& d) const {
  return ::boxplus::DescribeUndetermined(
      d, [this](int v) { return vars_[v]->name; }, [this](int v) { return vars_[v]->labels; });
}

void Problem::SetDirectionLabels(int id, std::vector<std::string> labels) {
  CheckVariable(id);
  BOXPLUS_CHECK(
      labels.empty() || static_cast<int>(labels.size()) == vars_[id]->manifold->TangentSize(),
      "variable '", vars_[id]->name, "': ", labels.size(), " labels for ",
      vars_[id]->manifold->TangentSize(), " tangent directions");
  vars_[id]->labels = std::move(labels);
}
const std::vector<std::string>& Problem::direction_labels(int id) const {
  CheckVariable(id);
  return vars_[id]->labels;
}

Eigen::MatrixXd Problem::Covariance(int id) { return JointCovariance({id}); }

Eigen::MatrixXd Problem::JointCovariance(const std::vector<int>& ids) {
  const Busy busy(*this, "Covariance");
  std::vector<int> offsets;
  int total = 0;
  std::set<int> seen;
  std::vector<std::string> untouched;
  for (int id : ids) {
    CheckVariable(id);
    BOXPLUS_CHECK(seen.insert(id).second, "joint covariance: variable '", vars_[id]->name,
                  "' is listed twice");
    BOXPLUS_CHECK(!vars_[id]->fixed, "variable '", vars_[id]->name,
                  "' is fixed: it has no covariance");
    if (vars_[id]->num_measurements == 0) untouched.push_back("'" + vars_[id]->name + "'");
    offsets.push_back(total);
    total += vars_[id]->manifold->TangentSize();
  }
  if (untouched.size() == 1) {
    throw ::boxplus::Error("variable " + untouched[0] +
                           " is not touched by any measurement: its covariance is undetermined");
  }
  if (!untouched.empty()) {
    std::string names = untouched[0];
    for (size_t k = 1; k < untouched.size(); ++k) names += ", " + untouched[k];
    throw ::boxplus::Error("variables " + names +
                           " are not touched by any measurement: their covariance is undetermined");
  }
  if (ids.empty()) return Eigen::MatrixXd(0, 0);
  std::string names;
  for (int id : ids) names += (names.empty() ? "'" : ", '") + vars_[id]->name + "'";
  // Ceres' covariance notices a rank-deficient Jacobian only when it has at
  // least as many rows as columns: the rank test decides.
  const Determinedness& determinedness = Determine({});
  const bool undetermined = std::any_of(ids.begin(), ids.end(),
                                        [&](int id) { return determinedness.Find(id) != nullptr; });
  if (undetermined) {
    throw ::boxplus::Error(
        "covariance of " + names + " is undefined: the measurements do not determine " +
        DescribeUndetermined(determinedness) + " (add measurements or priors, or fix a variable)");
  }
  if (!determinedness.determined()) {
    const SparseJacobianEvaluation j = SparseJacobian();
    std::vector<int> columns;
    for (int id : ids) {
      const auto it = std::find(j.variables.begin(), j.variables.end(), id);
      const int begin = j.column_offsets[it - j.variables.begin()];
      for (int c = 0; c < vars_[id]->manifold->TangentSize(); ++c) columns.push_back(begin + c);
    }
    return CovarianceOfDeterminedColumns(j.jacobian, determinedness, columns);
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
  BOXPLUS_CHECK(cov.Compute(pairs, CeresProblem()), "covariance of ", names,
                " is undefined: the measurements do not determine every "
                "parameter (rank-deficient Jacobian)");
  Eigen::MatrixXd out(total, total);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (size_t i = 0; i < ids.size(); ++i) {
    for (size_t j = i; j < ids.size(); ++j) {
      const int ni = vars_[ids[i]]->manifold->TangentSize();
      const int nj = vars_[ids[j]]->manifold->TangentSize();
      RowMajor block(ni, nj);
      cov.GetCovarianceBlockInTangentSpace(vars_[ids[i]]->data.get(), vars_[ids[j]]->data.get(),
                                           block.data());
      out.block(offsets[i], offsets[j], ni, nj) = block;
      out.block(offsets[j], offsets[i], nj, ni) = block.transpose();
    }
  }
  return out;
}

}  // namespace boxplus
