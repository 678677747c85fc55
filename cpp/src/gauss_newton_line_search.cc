#include "gauss_newton_line_search.h"

#include "boxplus/progress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace boxplus::internal {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Sufficient-decrease constant of the Armijo condition, and how often the
// step may be halved before the direction is given up.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 30;

// Sparse Cholesky of the normal equations, chosen once from the symbolic
// analysis. Pose graphs are mostly so sparse that a simplicial LDLᵀ (Eigen's,
// AMD-ordered, as g2o uses) beats CHOLMOD's supernodal LLᵀ, whose BLAS calls
// on tiny blocks cost more than they save (total factorisation time, best of
// 3: intel 5.1 vs 12.9 ms, parking-garage 49 vs 69 ms, smallGrid3D 19 vs 32
// ms); when the factor fills in, the supernodal one wins (sphere2500 541 vs
// 1468 ms). The switch is on Σ c²/Σ c over the column counts c of L: 9–52 on
// the 2D sets, parking-garage and tinyGrid3D, 96 on smallGrid3D, 299 on
// sphere2500 and 400 on torus3D.
class SparseCholesky {
 public:
  using Matrix = Eigen::SparseMatrix<double>;
  static constexpr double kSupernodalSwitch = 150.0;

  void Analyse(const Matrix& H) {
    simplicial_.analyzePattern(H);
    const double flops_per_nonzero = simplicial_.FlopsPerNonZero();
    supernodal_ = flops_per_nonzero > kSupernodalSwitch;
    if (supernodal_) cholmod_.analyzePattern(H);
  }
  bool Factorise(const Matrix& H, double shift) {
    if (supernodal_) {
      cholmod_.setShift(shift);
      cholmod_.factorize(H);
      return cholmod_.info() == Eigen::Success;
    }
    simplicial_.setShift(shift);
    simplicial_.factorize(H);
    return simplicial_.info() == Eigen::Success;
  }
  Eigen::VectorXd Solve(const Eigen::VectorXd& b) const {
    return supernodal_ ? Eigen::VectorXd(cholmod_.solve(b)) : Eigen::VectorXd(simplicial_.solve(b));
  }
  bool supernodal() const { return supernodal_; }

 private:
  // Eigen's LDLᵀ, telling the cost of its factorisation after the analysis.
  // The matrix arrives in a fill-reducing block order (Layout).
  class CountingLDLT
      : public Eigen::SimplicialLDLT<Matrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
   public:
    double FlopsPerNonZero() const {
      double flops = 0.0, nnz = 0.0;
      for (Eigen::Index j = 0; j < m_nonZerosPerCol.size(); ++j) {
        const double c = m_nonZerosPerCol[j];
        flops += c * c;
        nnz += c;
      }
      return nnz > 0 ? flops / nnz : 0.0;
    }
  };
  CountingLDLT simplicial_;
  Eigen::CholmodSupernodalLLT<Matrix, Eigen::Upper> cholmod_;
  bool supernodal_ = false;
};

class GaussNewtonLineSearch {
 public:
  GaussNewtonLineSearch(const std::vector<LsqBlock>& blocks, const std::vector<LsqTerm>& terms,
                        const SolverOptions& options, const PrepareEvaluation& prepare)
      : blocks_(blocks), terms_(terms), options_(options), prepare_(prepare) {}

  SolveSummary Run() {
    start_ = Clock::now();
    Layout();
    SaveAccepted();
    try {
      Minimise();
    } catch (...) {
      RestoreAccepted();  // never leave a trial point behind
      throw;
    }
    summary_.time_s = Seconds(start_);
    std::ostringstream r;
    r << "Gauss-Newton with backtracking line search (boxplus; "
      << (llt_.supernodal() ? "CHOLMOD supernodal LLT" : "Eigen simplicial LDLT")
      << ")\n"
      << "  parameter blocks " << blocks_.size() << " (" << free_.size() << " free), tangent size "
      << n_ << ", residual blocks " << terms_.size() << ", Hessian non-zeros (upper) "
      << H_.nonZeros() << "\n"
      << "  iterations " << summary_.iterations << ", step halvings " << halvings_ << "\n"
      << "  residual-only evaluations   " << cost_evals_ << ", " << cost_time_ << " s\n"
      << "  normal-equation assemblies  " << normal_evals_ << ", " << normal_time_ << " s\n"
      << "  symbolic analysis           " << analyse_time_ << " s\n"
      << "  factorisation and solve     " << solve_time_ << " s\n"
      << "  total                       " << summary_.time_s << " s\n"
      << "  termination: " << summary_.termination << " (" << summary_.message << ")\n";
    summary_.report = r.str();
    return summary_;
  }

 private:
  // Column offsets of the free blocks, the fixed sparsity pattern of the
  // upper triangle of JᵀJ (block (i, j), i ≤ j, stored whole), and for each
  // term where its blocks' products go.
  void Layout() {
    const int nb = static_cast<int>(blocks_.size());
    // Blocks no term depends on stay out of the system (as in Ceres).
    std::vector<bool> used(nb, false);
    for (const LsqTerm& term : terms_) {
      for (int b : term.blocks) used[b] = true;
    }
    std::vector<int> candidates;
    for (int b = 0; b < nb; ++b) {
      if (used[b] && !blocks_[b].fixed && blocks_[b].manifold->TangentSize() > 0) {
        candidates.push_back(b);
      }
    }
    // The free blocks in a fill-reducing elimination order: AMD on the block
    // graph (as g2o and Ceres order), 36× smaller than the scalar matrix, so
    // the scalar factorisation keeps its natural order.
    free_index_.assign(nb, -1);
    for (size_t k = 0; k < candidates.size(); ++k) free_index_[candidates[k]] = static_cast<int>(k);
    const Eigen::VectorXi order = BlockOrdering(static_cast<int>(candidates.size()));
    for (Eigen::Index k = 0; k < order.size(); ++k) {
      const int b = candidates[order[k]];
      free_index_[b] = static_cast<int>(k);
      free_.push_back(b);
      col_.push_back(n_);
      n_ += blocks_[b].manifold->TangentSize();
    }
    const int nf = static_cast<int>(free_.size());
    tangent_.resize(nf);
    for (int f = 0; f < nf; ++f) tangent_[f] = blocks_[free_[f]].manifold->TangentSize();

    std::vector<std::vector<int>> rows_of(nf);  // block rows i ≤ j of block column j
    term_free_.resize(terms_.size());
    params_.resize(terms_.size());
    for (size_t t = 0; t < terms_.size(); ++t) {
      std::vector<int>& fs = term_free_[t];
      for (int b : terms_[t].blocks) {
        params_[t].push_back(blocks_[b].x);
        if (free_index_[b] >= 0) fs.push_back(free_index_[b]);
      }
      std::vector<int> sorted = fs;
      std::sort(sorted.begin(), sorted.end());
      for (size_t a = 0; a < sorted.size(); ++a) {
        for (size_t c = a; c < sorted.size(); ++c) rows_of[sorted[c]].push_back(sorted[a]);
      }
    }
    for (int f = 0; f < nf; ++f) {
      std::vector<int>& v = rows_of[f];
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    }
    // Offset of block row i within the columns of block column j.
    std::vector<std::vector<int>> pos_in_col(nf);
    std::vector<int> column_height(nf, 0);
    long long nnz = 0;
    for (int f = 0; f < nf; ++f) {
      for (int i : rows_of[f]) {
        pos_in_col[f].push_back(column_height[f]);
        column_height[f] += tangent_[i];
      }
      nnz += static_cast<long long>(column_height[f]) * tangent_[f];
    }
    H_.resize(n_, n_);
    H_.resizeNonZeros(static_cast<Eigen::Index>(nnz));
    int* outer = H_.outerIndexPtr();
    int* inner = H_.innerIndexPtr();
    int k = 0;
    for (int f = 0; f < nf; ++f) {
      for (int c = 0; c < tangent_[f]; ++c) {
        outer[col_[f] + c] = k;
        for (int i : rows_of[f]) {
          for (int r = 0; r < tangent_[i]; ++r) inner[k++] = col_[i] + r;
        }
      }
    }
    outer[n_] = k;
    // For each term, each ordered pair (a, b) of its free blocks with
    // col(a) ≤ col(b): the offset of block a within block b's columns.
    pair_pos_.resize(terms_.size());
    for (size_t t = 0; t < terms_.size(); ++t) {
      const std::vector<int>& fs = term_free_[t];
      for (size_t a = 0; a < fs.size(); ++a) {
        for (size_t b = 0; b < fs.size(); ++b) {
          if (fs[a] > fs[b]) continue;
          const std::vector<int>& rows = rows_of[fs[b]];
          const auto it = std::lower_bound(rows.begin(), rows.end(), fs[a]);
          pair_pos_[t].push_back(pos_in_col[fs[b]][it - rows.begin()]);
        }
      }
    }
    g_.setZero(n_);
    plus_jacobian_.resize(nf);
  }

  // AMD order of the free blocks (free_index_ holding their provisional
  // numbers): order[k] is the provisional number of the k-th block.
  Eigen::VectorXi BlockOrdering(int nf) const {
    std::vector<Eigen::Triplet<double>> entries;
    for (int f = 0; f < nf; ++f) entries.emplace_back(f, f, 1.0);
    std::vector<int> fs;
    for (const LsqTerm& term : terms_) {
      fs.clear();
      for (int b : term.blocks) {
        if (free_index_[b] >= 0) fs.push_back(free_index_[b]);
      }
      for (int a : fs) {
        for (int c : fs) entries.emplace_back(a, c, 1.0);
      }
    }
    Eigen::SparseMatrix<double> pattern(nf, nf);
    pattern.setFromTriplets(entries.begin(), entries.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::AMDOrdering<int>()(pattern, perm);
    return perm.indices();
  }

  void SaveAccepted() {
    accepted_.clear();
    for (int b : free_) {
      const int a = blocks_[b].manifold->AmbientSize();
      accepted_.insert(accepted_.end(), blocks_[b].x, blocks_[b].x + a);
    }
  }
  void RestoreAccepted() {
    size_t k = 0;
    for (int b : free_) {
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
    Eigen::VectorXd d;
    for (size_t f = 0; f < free_.size(); ++f) {
      const LsqBlock& blk = blocks_[free_[f]];
      d = alpha * delta.segment(col_[f], tangent_[f]);
      if (!blk.manifold->Plus(accepted_.data() + k, d.data(), blk.x)) return false;
      k += blk.manifold->AmbientSize();
    }
    return true;
  }

  // ½ Σ ρ(‖r‖²) at the current values; false if a term cannot be evaluated.
  bool EvaluateCost(double* cost) {
    const auto t0 = Clock::now();
    ++cost_evals_;
    prepare_(false);
    double total = 0.0;
    for (size_t t = 0; t < terms_.size(); ++t) {
      const LsqTerm& term = terms_[t];
      residual_.resize(term.cost->num_residuals());
      if (!term.cost->Evaluate(params_[t].data(), residual_.data(), nullptr)) return false;
      total += HalfRho(term, residual_.squaredNorm(), nullptr);
    }
    cost_time_ += Seconds(t0);
    *cost = total;
    return std::isfinite(total);
  }

  static double HalfRho(const LsqTerm& term, double s, double* weight) {
    if (!term.loss) {
      if (weight) *weight = 1.0;
      return 0.5 * s;
    }
    double rho[3];
    term.loss->Evaluate(s, rho);
    if (weight) *weight = rho[1];
    return 0.5 * rho[0];
  }

  // Cost, gradient g = Σ w Jᵀr and H = Σ w JᵀJ (upper blocks) at the current
  // values, J in the tangent spaces of the free blocks.
  bool EvaluateNormalEquations(double* cost) {
    const auto t0 = Clock::now();
    ++normal_evals_;
    prepare_(true);
    for (size_t f = 0; f < free_.size(); ++f) {
      const ceres::Manifold& m = *blocks_[free_[f]].manifold;
      plus_jacobian_[f].resize(m.AmbientSize(), m.TangentSize());
      if (!m.PlusJacobian(blocks_[free_[f]].x, plus_jacobian_[f].data())) return false;
    }
    std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
    g_.setZero();
    const int* outer = H_.outerIndexPtr();
    double* values = H_.valuePtr();
    double total = 0.0;
    for (size_t t = 0; t < terms_.size(); ++t) {
      const LsqTerm& term = terms_[t];
      const int nr = term.cost->num_residuals();
      const auto& sizes = term.cost->parameter_block_sizes();
      const size_t np = term.blocks.size();
      residual_.resize(nr);
      ambient_jac_.resize(np);
      jac_ptrs_.assign(np, nullptr);
      for (size_t k = 0; k < np; ++k) {
        if (free_index_[term.blocks[k]] < 0) continue;
        ambient_jac_[k].resize(nr, sizes[k]);
        jac_ptrs_[k] = ambient_jac_[k].data();
      }
      if (!term.cost->Evaluate(params_[t].data(), residual_.data(), jac_ptrs_.data())) {
        return false;
      }
      double w = 1.0;
      total += HalfRho(term, residual_.squaredNorm(), &w);
      // Tangent Jacobians of the free blocks, in the order of term_free_.
      tangent_jac_.resize(term_free_[t].size());
      for (size_t k = 0, j = 0; k < np; ++k) {
        const int f = free_index_[term.blocks[k]];
        if (f < 0) continue;
        tangent_jac_[j++].noalias() = ambient_jac_[k] * plus_jacobian_[f];
      }
      const std::vector<int>& fs = term_free_[t];
      for (size_t a = 0; a < fs.size(); ++a) {
        g_.segment(col_[fs[a]], tangent_[fs[a]]).noalias() +=
            w * tangent_jac_[a].transpose() * residual_;
      }
      size_t p = 0;
      for (size_t a = 0; a < fs.size(); ++a) {
        for (size_t b = 0; b < fs.size(); ++b) {
          if (fs[a] > fs[b]) continue;
          block_.noalias() = w * tangent_jac_[a].transpose() * tangent_jac_[b];
          const int pos = pair_pos_[t][p++];
          for (int c = 0; c < tangent_[fs[b]]; ++c) {
            double* col = values + outer[col_[fs[b]] + c] + pos;
            for (int r = 0; r < tangent_[fs[a]]; ++r) col[r] += block_(r, c);
          }
        }
      }
    }
    normal_time_ += Seconds(t0);
    *cost = total;
    return std::isfinite(total) && g_.allFinite();
  }

  // δ = −H⁻¹g; a singular H (gauge not fixed, a parameter no term
  // determines) is regularised with the smallest shift λI that factorises.
  bool SolveStep(Eigen::VectorXd* delta) {
    auto t0 = Clock::now();
    if (!analysed_) {
      llt_.Analyse(H_);
      analysed_ = true;
      analyse_time_ += Seconds(t0);
      t0 = Clock::now();
    }
    double shift = 0.0;
    for (int attempt = 0; attempt < 8; ++attempt) {
      if (llt_.Factorise(H_, shift)) {
        *delta = llt_.Solve(-g_);
        solve_time_ += Seconds(t0);
        if (delta->allFinite()) return true;
      }
      // Only a failed factorisation pays for the scan of the diagonal.
      shift = shift == 0.0 ? 1e-12 * std::max(1.0, H_.diagonal().cwiseAbs().maxCoeff())
                           : shift * 100.0;
    }
    solve_time_ += Seconds(t0);
    return false;
  }

  void Report(const IterationInfo& info) {
    if (options_.verbose) {
      if (info.iteration == 0) std::fprintf(stderr, "%s\n", ProgressHeader().c_str());
      std::fprintf(stderr, "%s\n", FormatProgress(info).c_str());
    }
    if (options_.on_iteration && !options_.on_iteration(info)) interrupted_ = true;
  }

  void Finish(const char* termination, const std::string& message, bool usable) {
    summary_.termination = termination;
    summary_.message = message;
    summary_.usable = usable;
  }

  void Minimise() {
    double cost = 0.0;
    summary_.iterations = 0;
    if (!EvaluateNormalEquations(&cost)) {
      RestoreAccepted();
      summary_.initial_cost = summary_.final_cost = std::numeric_limits<double>::quiet_NaN();
      return Finish("failure", "the residuals or Jacobians cannot be evaluated at the start",
                    false);
    }
    summary_.initial_cost = summary_.final_cost = cost;
    IterationInfo info;
    info.cost = cost;
    info.gradient_max_norm = g_.lpNorm<Eigen::Infinity>();
    info.trust_region_radius = 0.0;  // no trust region: FormatProgress shows α
    info.step_length = 1.0;
    info.step_is_successful = true;
    info.cumulative_time_s = info.iteration_time_s = Seconds(start_);
    Report(info);
    Eigen::VectorXd delta;
    for (int it = 1;; ++it) {
      if (interrupted_) return Finish("interrupted", "stopped by the iteration callback", true);
      const double gmax = g_.lpNorm<Eigen::Infinity>();
      if (gmax <= options_.gradient_tolerance) {
        return Finish("convergence", "gradient tolerance reached: max |g| = " +
                                         std::to_string(gmax), true);
      }
      if (it > options_.max_iterations) {
        return Finish("no_convergence", "maximum number of iterations reached", true);
      }
      const auto t_it = Clock::now();
      if (!SolveStep(&delta)) {
        return Finish("failure", "the normal equations could not be factorised", false);
      }
      const double slope = g_.dot(delta);
      if (!(slope < 0.0)) {
        return Finish("convergence", "the Gauss-Newton step is not a descent direction "
                                     "(the gradient is numerically zero)", true);
      }
      double alpha = 1.0, trial = 0.0;
      bool accepted = false;
      for (int h = 0; h <= kMaxHalvings; ++h, alpha *= 0.5) {
        if (h > 0) ++halvings_;
        if (Step(delta, alpha) && EvaluateCost(&trial) &&
            trial <= cost + kArmijo * alpha * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        RestoreAccepted();
        return Finish("convergence", "the line search found no decrease along the "
                                     "Gauss-Newton direction", true);
      }
      const double old_cost = cost;
      const double step_norm = alpha * delta.norm();
      const double x_norm = AcceptedNorm();
      SaveAccepted();
      summary_.iterations = it;
      summary_.final_cost = trial;
      if (!EvaluateNormalEquations(&cost)) {
        return Finish("failure", "the Jacobians cannot be evaluated at the accepted point",
                      true);
      }
      info.iteration = it;
      info.cost = cost;
      info.cost_change = old_cost - cost;
      info.gradient_max_norm = g_.lpNorm<Eigen::Infinity>();
      info.step_norm = step_norm;
      info.trust_region_radius = 0.0;
      info.step_length = alpha;
      info.iteration_time_s = Seconds(t_it);
      info.cumulative_time_s = Seconds(start_);
      info.step_is_successful = true;
      Report(info);
      if (std::abs(old_cost - cost) <= options_.function_tolerance * old_cost) {
        return Finish("convergence", "function tolerance reached: |Δcost|/cost = " +
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

  std::vector<int> free_;        // free block indices, in column order
  std::vector<int> free_index_;  // block → free index or −1
  std::vector<int> col_;         // first column of each free block
  std::vector<int> tangent_;     // tangent size of each free block
  int n_ = 0;
  std::vector<std::vector<int>> term_free_;
  std::vector<std::vector<const double*>> params_;
  std::vector<std::vector<int>> pair_pos_;

  Eigen::SparseMatrix<double> H_;
  Eigen::VectorXd g_;
  SparseCholesky llt_;
  bool analysed_ = false;
  std::vector<RowMajor> plus_jacobian_;
  std::vector<double> accepted_;

  // Scratch reused across terms.
  Eigen::VectorXd residual_;
  std::vector<RowMajor> ambient_jac_;
  std::vector<double*> jac_ptrs_;
  std::vector<Eigen::MatrixXd> tangent_jac_;
  Eigen::MatrixXd block_;

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
