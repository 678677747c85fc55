#include "boxplus/certify/staircase.h"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>

#include "../slam/nearest_rotation.h"
#include "boxplus/errors.h"
#include "newton_polish.h"
#include "stiefel_manifold.h"

namespace boxplus::certify {
namespace {

using SpMat = Eigen::SparseMatrix<double>;
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One edge of the rank-r problem: r = [√κ (Yⱼ − YᵢR̃), √τ (tⱼ − tᵢ − Yᵢt̃)],
// linear in the blocks (tᵢ, tⱼ, Yᵢ, Yⱼ), Y column by column; Σ‖r‖² is the
// edge's term of f.
class LiftedEdgeCost : public ceres::CostFunction {
 public:
  LiftedEdgeCost(int r, const SESyncGraph::Edge& e)
      : r_(r),
        d_(static_cast<int>(e.t.size())),
        sk_(std::sqrt(e.kappa)),
        st_(std::sqrt(e.tau)),
        R_(e.R),
        t_(e.t) {
    set_num_residuals(r_ * d_ + r_);
    *mutable_parameter_block_sizes() = {r_, r_, r_ * d_, r_ * d_};
  }

  bool Evaluate(double const* const* p, double* residuals, double** jac) const override {
    const Eigen::Map<const Eigen::VectorXd> ti(p[0], r_), tj(p[1], r_);
    const Eigen::Map<const Eigen::MatrixXd> Yi(p[2], r_, d_), Yj(p[3], r_, d_);
    Eigen::Map<Eigen::MatrixXd>(residuals, r_, d_) = sk_ * (Yj - Yi * R_);
    Eigen::Map<Eigen::VectorXd>(residuals + r_ * d_, r_) = st_ * (tj - ti - Yi * t_);
    if (!jac) return true;
    const int m = num_residuals();
    if (jac[0]) {
      Eigen::Map<RowMajor> J(jac[0], m, r_);
      J.setZero();
      J.bottomRows(r_).diagonal().setConstant(-st_);
    }
    if (jac[1]) {
      Eigen::Map<RowMajor> J(jac[1], m, r_);
      J.setZero();
      J.bottomRows(r_).diagonal().setConstant(st_);
    }
    if (jac[2]) {
      Eigen::Map<RowMajor> J(jac[2], m, r_ * d_);
      J.setZero();
      for (int a = 0; a < r_; ++a) {
        for (int b = 0; b < d_; ++b) {
          for (int c = 0; c < d_; ++c) J(c * r_ + a, b * r_ + a) = -sk_ * R_(b, c);
          J(r_ * d_ + a, b * r_ + a) = -st_ * t_[b];
        }
      }
    }
    if (jac[3]) {
      Eigen::Map<RowMajor> J(jac[3], m, r_ * d_);
      J.setZero();
      J.topRows(r_ * d_).diagonal().setConstant(sk_);
    }
    return true;
  }

 private:
  int r_, d_;
  double sk_, st_;
  Eigen::MatrixXd R_;
  Eigen::VectorXd t_;
};

class StopWhen : public ceres::IterationCallback {
 public:
  explicit StopWhen(std::function<bool()> stop) : stop_(std::move(stop)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return stop_ && stop_() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<bool()> stop_;
};

// Solves the rank-r relaxation from X (r × (n + dn)) in place; returns the
// iterations taken.
int SolveRank(const SESyncGraph& g, Eigen::MatrixXd* X, const StaircaseOptions& options,
              bool* interrupted) {
  const int r = static_cast<int>(X->rows()), d = g.d, n = g.n;
  std::vector<Eigen::VectorXd> t(n);
  std::vector<Eigen::VectorXd> Y(n);  // column by column
  for (int i = 0; i < n; ++i) {
    t[i] = X->col(i);
    Y[i] = Eigen::Map<const Eigen::VectorXd>(X->middleCols(n + d * i, d).eval().data(), r * d);
  }
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  internal::StiefelManifold stiefel(r, d);
  for (const SESyncGraph::Edge& e : g.edges) {
    problem.AddResidualBlock(new LiftedEdgeCost(r, e), nullptr,
                             {t[e.i].data(), t[e.j].data(), Y[e.i].data(), Y[e.j].data()});
  }
  for (int i = 0; i < n; ++i) {
    problem.SetManifold(Y[i].data(), &stiefel);
  }
  problem.SetParameterBlockConstant(t[g.anchor].data());

  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-15;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-15;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  StopWhen stop(options.interrupted);
  so.callbacks.push_back(&stop);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  *interrupted = options.interrupted && options.interrupted();
  for (int i = 0; i < n; ++i) {
    X->col(i) = t[i];
    X->middleCols(n + d * i, d) = Eigen::Map<const Eigen::MatrixXd>(Y[i].data(), r, d);
  }
  return static_cast<int>(summary.iterations.size());
}

// [Y; 0] + α [0; vᵀ] with each rotation block retracted to St(d, r + 1), the
// α of a backtracking search for a decrease of f (the direction is one of
// second-order descent, so small steps decrease f by about α² λ_min).
Eigen::MatrixXd Escape(const SESyncGraph& g, const Eigen::MatrixXd& Y, const Eigen::VectorXd& v) {
  const int r = static_cast<int>(Y.rows()), d = g.d, n = g.n;
  const double f0 = g.Objective(Y);
  Eigen::MatrixXd best;
  for (double alpha = std::sqrt(static_cast<double>(n)); alpha > 1e-10; alpha *= 0.5) {
    Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(r + 1, Y.cols());
    Z.topRows(r) = Y;
    Z.row(r) = alpha * v.transpose();
    for (int i = 0; i < n; ++i) {
      Z.middleCols(n + d * i, d) = internal::OrthonormalFactor(Z.middleCols(n + d * i, d));
    }
    Z.leftCols(n).colwise() -= Eigen::VectorXd(Z.col(g.anchor));
    if (g.Objective(Z) < f0) return Z;
    if (best.size() == 0) best = Z;
  }
  return best;  // no decrease found (λ_min ≈ 0): start from the largest step
}

}  // namespace

Eigen::MatrixXd RoundSolution(const SESyncGraph& g, const SpMat& M, const Eigen::MatrixXd& Y) {
  const int d = g.d, n = g.n;
  const Eigen::MatrixXd YR = Y.rightCols(d * n);
  Eigen::MatrixXd R(d, d * n);
  if (Y.rows() == d) {
    R = YR;
  } else {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(YR * YR.transpose(), Eigen::ComputeFullU);
    R = svd.matrixU().leftCols(d).transpose() * YR;  // Σ_d V_dᵀ
  }
  int positive = 0;
  for (int i = 0; i < n; ++i) positive += R.middleCols(d * i, d).determinant() > 0;
  if (2 * positive < n) R.row(d - 1) *= -1.0;
  for (int i = 0; i < n; ++i) {
    R.middleCols(d * i, d) = slam::NearestRotation(R.middleCols(d * i, d));
  }
  // Translations optimal for R: minimise tr(X M Xᵀ) over t with the anchor's
  // held at zero, i.e. L t = −M_tR Rᵀ on the other rows.
  std::vector<int> keep(n, -1);
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (i != g.anchor) keep[i] = m++;
  }
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m, d);
  const Eigen::MatrixXd Rt = R.transpose();
  for (int k = 0; k < n; ++k) {
    for (SpMat::InnerIterator it(M, k); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (keep[k] < 0) continue;
      if (row < n) {
        if (keep[row] >= 0) trip.emplace_back(keep[row], keep[k], it.value());
      } else {
        rhs.row(keep[k]) -= it.value() * Rt.row(row - n);
      }
    }
  }
  SpMat L(m, m);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<SpMat> ldlt(L);
  BOXPLUS_CHECK(ldlt.info() == Eigen::Success,
                "certificate: the translation system of the rounded solution is singular");
  const Eigen::MatrixXd t = ldlt.solve(rhs);
  Eigen::MatrixXd X(d, n + d * n);
  X.rightCols(d * n) = R;
  for (int i = 0; i < n; ++i) {
    X.col(i) =
        keep[i] >= 0 ? Eigen::VectorXd(t.row(keep[i]).transpose()) : Eigen::VectorXd::Zero(d);
  }
  return X;
}

StaircaseResult RiemannianStaircase(const SESyncGraph& g, const SpMat& M, const Eigen::MatrixXd& X,
                                    const Certificate& first, const StaircaseOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  StaircaseResult out;
  out.rank = g.d;
  out.relaxation_objective = first.objective;
  out.lower_bound = first.lower_bound;
  Eigen::MatrixXd Y = X;
  Certificate cert = first;
  while (!cert.certified && static_cast<int>(Y.rows()) < options.max_rank &&
         cert.eigenvector.size() == Y.cols()) {
    Y = Escape(g, Y, cert.eigenvector);
    bool interrupted = false;
    out.iterations += SolveRank(g, &Y, options, &interrupted);
    if (!interrupted) internal::NewtonPolish(g, M, &Y);
    out.rank = static_cast<int>(Y.rows());
    cert = Certify(g, M, Y, options.certificate);
    out.certificates.push_back(cert);
    out.relaxation_objective = cert.objective;
    if (interrupted) {
      out.interrupted = true;
      break;
    }
  }
  out.relaxation_certified = cert.certified && out.rank > g.d;
  out.lower_bound = cert.lower_bound;
  out.rounded = RoundSolution(g, M, Y);
  out.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace boxplus::certify
