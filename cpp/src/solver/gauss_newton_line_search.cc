#include "gauss_newton_line_search.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>

#include <Eigen/Core>

#include "boxplus/progress.h"
#include "normal_equations.h"
#include "sparse_cholesky.h"

namespace boxplus::internal {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Sufficient-decrease constant of the Armijo condition, and how often the
// step may be halved before the direction is given up.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 30;

class GaussNewtonLineSearch {
 public:
  GaussNewtonLineSearch(const std::vector<LsqBlock>& blocks, const std::vector<LsqTerm>& terms,
                        const SolverOptions& options, const PrepareEvaluation& prepare)
      : blocks_(blocks),
        terms_(terms),
        options_(options),
        prepare_(prepare),
        normal_(blocks, terms, options.num_threads) {}

  SolveSummary Run() {
    start_ = Clock::now();
    SaveAccepted();
    try {
      Minimise();
    } catch (...) {
      RestoreAccepted();  // never leave a trial point behind
      throw;
    }
    summary_.time_s = Seconds(start_);
    summary_.report = Report();
    return summary_;
  }

 private:
  std::string Report() const {
    std::ostringstream r;
    r << "Gauss-Newton with backtracking line search (boxplus; " << cholesky_.name() << ")\n"
      << "  parameter blocks " << blocks_.size() << " (" << normal_.free_blocks().size()
      << " free), tangent size " << normal_.tangent_size() << ", residual blocks " << terms_.size()
      << ", Hessian non-zeros (upper) " << normal_.hessian().nonZeros() << "\n"
      << "  iterations " << summary_.iterations << ", step halvings " << halvings_ << "\n"
      << "  residual-only evaluations   " << cost_evals_ << ", " << cost_time_ << " s\n"
      << "  normal-equation assemblies  " << normal_evals_ << ", " << normal_time_ << " s\n"
      << "  symbolic analysis           " << analyse_time_ << " s\n"
      << "  factorisation and solve     " << solve_time_ << " s\n"
      << "  total                       " << summary_.time_s << " s\n"
      << "  termination: " << summary_.termination << " (" << summary_.message << ")\n";
    return r.str();
  }

  void SaveAccepted() {
    accepted_.clear();
    for (int b : normal_.free_blocks()) {
      const int a = blocks_[b].manifold->AmbientSize();
      accepted_.insert(accepted_.end(), blocks_[b].x, blocks_[b].x + a);
    }
  }
  void RestoreAccepted() {
    size_t k = 0;
    for (int b : normal_.free_blocks()) {
      const int a = blocks_[b].manifold->AmbientSize();
      std::copy(accepted_.begin() + k, accepted_.begin() + k + a, blocks_[b].x);
      k += a;
    }
  }
  double AcceptedNorm() const {
    return Eigen::Map<const Eigen::VectorXd>(accepted_.data(), accepted_.size()).norm();
  }
  // x = accepted ⊞ αδ, block by block.
  bool Step(const Eigen::VectorXd& delta, double alpha) {
    size_t k = 0;
    const std::vector<int>& free = normal_.free_blocks();
    for (size_t f = 0; f < free.size(); ++f) {
      const LsqBlock& blk = blocks_[free[f]];
      step_ = alpha * delta.segment(normal_.column(f), normal_.tangent(f));
      if (!blk.manifold->Plus(accepted_.data() + k, step_.data(), blk.x)) return false;
      k += blk.manifold->AmbientSize();
    }
    return true;
  }

  // An evaluation at the current values (cost only, or the normal
  // equations), after the evaluation hooks, counted and timed.
  bool Evaluate(bool normal_equations, double* cost) {
    const auto t0 = Clock::now();
    prepare_(normal_equations);
    const bool ok = normal_equations ? normal_.Assemble(cost) : normal_.EvaluateCost(cost);
    ++(normal_equations ? normal_evals_ : cost_evals_);
    (normal_equations ? normal_time_ : cost_time_) += Seconds(t0);
    return ok;
  }
  // δ = −H⁻¹g.
  bool SolveStep(Eigen::VectorXd* delta) {
    auto t0 = Clock::now();
    if (!analysed_) {
      cholesky_.Analyse(normal_.hessian());
      analysed_ = true;
      analyse_time_ += Seconds(t0);
      t0 = Clock::now();
    }
    const bool ok = cholesky_.Solve(normal_.hessian(), -normal_.gradient(), delta);
    solve_time_ += Seconds(t0);
    return ok;
  }
  double GradientMaxNorm() const {
    return normal_.tangent_size() == 0 ? 0.0 : normal_.gradient().lpNorm<Eigen::Infinity>();
  }

  void Progress(const IterationInfo& info) {
    if (options_.verbose) {
      if (info.iteration == 0) std::fprintf(stderr, "%s\n", ProgressHeader().c_str());
      std::fprintf(stderr, "%s\n", FormatProgress(info).c_str());
    }
    if (options_.on_iteration && !options_.on_iteration(info)) interrupted_ = true;
  }

  bool StopRequested() {
    if (!interrupted_ && options_.should_stop && options_.should_stop()) interrupted_ = true;
    return interrupted_;
  }

  void Finish(const char* termination, const std::string& message, bool usable) {
    summary_.termination = termination;
    summary_.message = message;
    summary_.usable = usable;
  }

  void Minimise() {
    double cost = 0.0;
    summary_.iterations = 0;
    if (!Evaluate(true, &cost)) {
      RestoreAccepted();
      summary_.initial_cost = summary_.final_cost = std::numeric_limits<double>::quiet_NaN();
      return Finish("failure", "the residuals or Jacobians cannot be evaluated at the start",
                    false);
    }
    summary_.initial_cost = summary_.final_cost = cost;
    IterationInfo info;
    info.cost = cost;
    info.gradient_max_norm = GradientMaxNorm();
    info.trust_region_radius = 0.0;  // no trust region: FormatProgress shows α
    info.step_length = 1.0;
    info.step_is_successful = true;
    info.cumulative_time_s = info.iteration_time_s = Seconds(start_);
    Progress(info);
    Eigen::VectorXd delta;
    for (int it = 1;; ++it) {
      if (interrupted_) return Finish("interrupted", "stopped by the iteration callback", true);
      const double gmax = GradientMaxNorm();
      if (normal_.tangent_size() == 0) {
        return Finish("convergence", "no free variable is touched by a measurement", true);
      }
      if (gmax <= options_.gradient_tolerance) {
        return Finish("convergence",
                      "gradient tolerance reached: max |g| = " + std::to_string(gmax), true);
      }
      if (it > options_.max_iterations) {
        return Finish("no_convergence", "maximum number of iterations reached", true);
      }
      const auto t_it = Clock::now();
      if (!SolveStep(&delta)) {
        return Finish("failure", "the normal equations could not be factorised", false);
      }
      if (StopRequested()) return Finish("interrupted", "stopped within an iteration", true);
      const double slope = normal_.gradient().dot(delta);
      if (!(slope < 0.0)) {
        return Finish("convergence",
                      "the Gauss-Newton step is not a descent direction "
                      "(the gradient is numerically zero)",
                      true);
      }
      double alpha = 1.0, trial = 0.0;
      bool accepted = false;
      for (int h = 0; h <= kMaxHalvings; ++h, alpha *= 0.5) {
        if (h > 0) ++halvings_;
        if (h > 0 && StopRequested()) {
          RestoreAccepted();
          return Finish("interrupted", "stopped within an iteration", true);
        }
        if (Step(delta, alpha) && Evaluate(false, &trial) &&
            trial <= cost + kArmijo * alpha * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        RestoreAccepted();
        return Finish("convergence", kNoDecreaseMessage, true);
      }
      const double old_cost = cost;
      const double step_norm = alpha * delta.norm();
      const double x_norm = AcceptedNorm();
      SaveAccepted();
      summary_.iterations = it;
      summary_.final_cost = trial;
      if (!Evaluate(true, &cost)) {
        return Finish("failure", "the Jacobians cannot be evaluated at the accepted point", true);
      }
      info.iteration = it;
      info.cost = cost;
      info.cost_change = old_cost - cost;
      info.gradient_max_norm = GradientMaxNorm();
      info.step_norm = step_norm;
      info.trust_region_radius = 0.0;
      info.step_length = alpha;
      info.iteration_time_s = Seconds(t_it);
      info.cumulative_time_s = Seconds(start_);
      info.step_is_successful = true;
      Progress(info);
      if (std::abs(old_cost - cost) <= options_.function_tolerance * old_cost) {
        return Finish("convergence",
                      "function tolerance reached: |Δcost|/cost = " +
                          std::to_string(std::abs(old_cost - cost) / old_cost),
                      true);
      }
      if (step_norm <= options_.parameter_tolerance * (x_norm + options_.parameter_tolerance)) {
        return Finish("convergence", "parameter tolerance reached", true);
      }
    }
  }

  const std::vector<LsqBlock>& blocks_;
  const std::vector<LsqTerm>& terms_;
  const SolverOptions& options_;
  const PrepareEvaluation& prepare_;

  NormalEquations normal_;
  SparseCholesky cholesky_;
  bool analysed_ = false;
  std::vector<double> accepted_;  // ambient values of the free blocks at the accepted point
  Eigen::VectorXd step_;

  SolveSummary summary_;
  bool interrupted_ = false;
  Clock::time_point start_;
  int cost_evals_ = 0, normal_evals_ = 0, halvings_ = 0;
  double cost_time_ = 0, normal_time_ = 0, analyse_time_ = 0, solve_time_ = 0;
};

}  // namespace

SolveSummary SolveGaussNewtonLineSearch(const std::vector<LsqBlock>& blocks,
                                        const std::vector<LsqTerm>& terms,
                                        const SolverOptions& options,
                                        const PrepareEvaluation& prepare) {
  return GaussNewtonLineSearch(blocks, terms, options, prepare).Run();
}

}  // namespace boxplus::internal
