#include "boxplus/certify/certificate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <sstream>

#include <Eigen/CholmodSupport>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include "../solver/sparse_cholesky.h"
#include "boxplus/errors.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/manifolds/se2.h"
#include "boxplus/manifolds/se3.h"

namespace boxplus::certify {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

std::string Where(const io::Graph& g, int line) {
  std::string s = g.name.empty() ? "" : io::Escaped(g.name);
  if (!s.empty() && line > 0) s += ":" + std::to_string(line);
  return s.empty() ? "" : s + ": ";
}

// Tells whether A = S + shift·D is positive definite, by one sparse Cholesky
// factorisation (the pattern analysed once), and solves with the last
// factor. The factorisation is CHOLMOD's supernodal one where the factor fills
// in and Eigen's simplicial one elsewhere (the rule of the line-search
// Gauss–Newton's solver, internal::SparseCholesky).
class DefinitenessTest {
 public:
  DefinitenessTest(const SpMat& S, const Eigen::VectorXd& D) : S_(S), D_(D) {
    const SpMat upper = S.triangularView<Eigen::Upper>();
    supernodal_ = internal::FillMeasure(internal::CholeskyColumnCounts(upper)) >
                  internal::SparseCholesky::kSupernodalSwitch;
    // A failed factorisation is an answer here, not an error to print.
    cholmod_.cholmod().print = 0;
    if (supernodal_) {
      cholmod_.analyzePattern(S_);
    } else {
      simplicial_.analyzePattern(S_);
    }
  }

  // Whether S + shift·D ≻ 0 (numerically: the factorisation succeeds).
  bool PositiveDefinite(double shift) {
    SpMat A = S_;
    for (int k = 0; k < A.outerSize(); ++k) {
      if (D_[k] != 0.0) A.coeffRef(k, k) += shift * D_[k];
    }
    if (supernodal_) {
      cholmod_.factorize(A);
      ok_ = cholmod_.info() == Eigen::Success;
    } else {
      simplicial_.factorize(A);
      ok_ = simplicial_.info() == Eigen::Success;
    }
    return ok_;
  }

  // (S + shift·D)⁻¹ b with the last successful factorisation.
  Eigen::VectorXd Solve(const Eigen::VectorXd& b) {
    return supernodal_ ? Eigen::VectorXd(cholmod_.solve(b)) : Eigen::VectorXd(simplicial_.solve(b));
  }

 private:
  const SpMat& S_;
  const Eigen::VectorXd& D_;
  bool supernodal_ = false;
  bool ok_ = false;
  Eigen::SimplicialLLT<SpMat, Eigen::Lower> simplicial_;
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> cholmod_;
};

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

SESyncGraph SESyncGraph::FromGraph(const io::Graph& g, int anchor_id) {
  SESyncGraph s;
  s.d = g.dimension;
  std::vector<int> pose_of(g.vertices.size(), -1);
  for (size_t v = 0; v < g.vertices.size(); ++v) {
    const io::Vertex& vx = g.vertices[v];
    BOXPLUS_CHECK(vx.kind == io::VertexKind::kSE2 || vx.kind == io::VertexKind::kSE3,
                  Where(g, vx.line), "certificate: vertex ", vx.id,
                  " is a landmark; SE-Sync's certificate covers graphs of poses only");
    pose_of[v] = s.n++;
    s.vertex_of.push_back(static_cast<int>(v));
  }
  BOXPLUS_CHECK(s.n > 0 && (s.d == 2 || s.d == 3), Where(g, 0),
                "certificate: the graph has no pose vertex");
  for (const io::Edge& e : g.edges) {
    BOXPLUS_CHECK(e.kind == io::EdgeKind::kSE2 || e.kind == io::EdgeKind::kSE3, Where(g, e.line),
                  "certificate: edge ", e.from, " -> ", e.to,
                  " is not a relative pose between two poses; SE-Sync's certificate covers "
                  "EDGE_SE2 / EDGE_SE3:QUAT (and TORO's EDGE2 / EDGE3 / EQUIV) only");
    Edge x;
    x.i = pose_of[g.EndIndex(e, 0)];
    x.j = pose_of[g.EndIndex(e, 1)];
    const ChordalPrecisions p = ChordalPrecisionsOfInformation(e.information);
    x.kappa = p.kappa;
    x.tau = p.tau;
    if (s.d == 2) {
      x.R = Eigen::Rotation2Dd(e.measurement[2]).toRotationMatrix();
      x.t = e.measurement.head<2>();
    } else {
      x.R = SE3::FromAmbient(e.measurement.data()).transform().topLeftCorner<3, 3>();
      x.t = e.measurement.head<3>();
    }
    BOXPLUS_CHECK(std::isfinite(x.kappa) && std::isfinite(x.tau) && x.kappa > 0 && x.tau > 0,
                  Where(g, e.line), "certificate: edge ", e.from, " -> ", e.to,
                  " has weights kappa = ", x.kappa, ", tau = ", x.tau,
                  " (from its information matrix); both must be positive and finite");
    s.edges.push_back(std::move(x));
  }
  s.anchor = anchor_id >= 0 ? pose_of[g.VertexIndex(anchor_id)] : 0;
  // The certificate's translation block is positive definite only when every
  // pose is connected to the anchor.
  std::vector<std::vector<int>> adj(s.n);
  for (const Edge& x : s.edges) {
    adj[x.i].push_back(x.j);
    adj[x.j].push_back(x.i);
  }
  std::vector<char> seen(s.n, 0);
  std::queue<int> q;
  q.push(s.anchor);
  seen[s.anchor] = 1;
  while (!q.empty()) {
    const int a = q.front();
    q.pop();
    for (int b : adj[a]) {
      if (!seen[b]) {
        seen[b] = 1;
        q.push(b);
      }
    }
  }
  for (int i = 0; i < s.n; ++i) {
    const io::Vertex& vx = g.vertices[s.vertex_of[i]];
    BOXPLUS_CHECK(seen[i], Where(g, vx.line), "certificate: pose ", vx.id,
                  " is not connected to pose ", g.vertices[s.vertex_of[s.anchor]].id,
                  " by relative-pose edges");
  }
  return s;
}

SpMat SESyncGraph::DataMatrix() const {
  const int N = n + d * n;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(edges.size() * (4 * d * d + 4 + 4 * d + d * d));
  auto rot = [&](int pose) { return n + d * pose; };
  for (const Edge& e : edges) {
    const int ri = rot(e.i), rj = rot(e.j);
    // κ B Bᵀ, X B = Rⱼ − RᵢR̃ (R̃R̃ᵀ = I).
    for (int a = 0; a < d; ++a) {
      trip.emplace_back(ri + a, ri + a, e.kappa);
      trip.emplace_back(rj + a, rj + a, e.kappa);
      for (int b = 0; b < d; ++b) {
        trip.emplace_back(ri + a, rj + b, -e.kappa * e.R(a, b));
        trip.emplace_back(rj + b, ri + a, -e.kappa * e.R(a, b));
      }
    }
    // τ b bᵀ, X b = tⱼ − tᵢ − Rᵢt̃.
    trip.emplace_back(e.i, e.i, e.tau);
    trip.emplace_back(e.j, e.j, e.tau);
    trip.emplace_back(e.i, e.j, -e.tau);
    trip.emplace_back(e.j, e.i, -e.tau);
    for (int a = 0; a < d; ++a) {
      trip.emplace_back(e.i, ri + a, e.tau * e.t[a]);
      trip.emplace_back(ri + a, e.i, e.tau * e.t[a]);
      trip.emplace_back(e.j, ri + a, -e.tau * e.t[a]);
      trip.emplace_back(ri + a, e.j, -e.tau * e.t[a]);
      for (int b = 0; b < d; ++b) trip.emplace_back(ri + a, ri + b, e.tau * e.t[a] * e.t[b]);
    }
  }
  SpMat M(N, N);
  M.setFromTriplets(trip.begin(), trip.end());
  return M;
}

Eigen::MatrixXd SESyncGraph::Stack(const io::Graph& g) const {
  Eigen::MatrixXd X(d, n + d * n);
  for (int i = 0; i < n; ++i) {
    const io::Vertex& v = g.vertices[vertex_of[i]];
    if (d == 2) {
      const SE2 x = SE2::FromAmbient(v.estimate.data());
      X.col(i) = x.transform().topRightCorner<2, 1>();
      X.block(0, n + 2 * i, 2, 2) = x.transform().topLeftCorner<2, 2>();
    } else {
      const SE3 x = SE3::FromAmbient(v.estimate.data());
      X.col(i) = x.transform().topRightCorner<3, 1>();
      X.block(0, n + 3 * i, 3, 3) = x.transform().topLeftCorner<3, 3>();
    }
  }
  const Eigen::VectorXd t0 = X.col(anchor);
  X.leftCols(n).colwise() -= t0;
  return X;
}

void SESyncGraph::Unstack(const Eigen::MatrixXd& X, const Eigen::VectorXd& anchor_translation,
                          io::Graph* g) const {
  BOXPLUS_CHECK(X.rows() == d && X.cols() == n + d * n, "certificate: X must be ", d, " x ",
                n + d * n);
  const Eigen::VectorXd shift = anchor_translation - X.col(anchor);
  for (int i = 0; i < n; ++i) {
    io::Vertex& v = g->vertices[vertex_of[i]];
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner(d, d) = X.block(0, n + d * i, d, d);
    T.topRightCorner(d, 1) = X.col(i) + shift;
    if (d == 2) {
      Eigen::Matrix3d T2 = Eigen::Matrix3d::Identity();
      T2.topLeftCorner<2, 2>() = T.topLeftCorner<2, 2>();
      T2.topRightCorner<2, 1>() = T.topRightCorner<2, 1>();
      v.estimate = SE2::FromMatrix(T2).ambient();
    } else {
      v.estimate = SE3::FromMatrix(T).ambient();
    }
    v.has_estimate = true;
  }
}

Eigen::MatrixXd SESyncGraph::TimesM(const Eigen::MatrixXd& X) const {
  const int r = static_cast<int>(X.rows());
  Eigen::MatrixXd XM = Eigen::MatrixXd::Zero(r, X.cols());
  for (const Edge& e : edges) {
    const auto Yi = X.middleCols(n + d * e.i, d);
    const Eigen::MatrixXd rR = X.middleCols(n + d * e.j, d) - Yi * e.R;
    const Eigen::VectorXd rt = X.col(e.j) - X.col(e.i) - Yi * e.t;
    XM.col(e.i) -= e.tau * rt;
    XM.col(e.j) += e.tau * rt;
    XM.middleCols(n + d * e.i, d) -= e.kappa * rR * e.R.transpose() + e.tau * rt * e.t.transpose();
    XM.middleCols(n + d * e.j, d) += e.kappa * rR;
  }
  return XM;
}

double SESyncGraph::Objective(const Eigen::MatrixXd& X) const {
  double f = 0.0;
  for (const Edge& e : edges) {
    const auto Yi = X.middleCols(n + d * e.i, d);
    f += e.kappa * (X.middleCols(n + d * e.j, d) - Yi * e.R).squaredNorm() +
         e.tau * (X.col(e.j) - X.col(e.i) - Yi * e.t).squaredNorm();
  }
  return f;
}

double SESyncObjective(const SpMat& M, const Eigen::MatrixXd& X) {
  const Eigen::MatrixXd XM = X * M;
  return XM.cwiseProduct(X).sum();
}

CertificateParts ComputeCertificateParts(const SESyncGraph& g, const SpMat& M,
                                         const Eigen::MatrixXd& X) {
  const int d = g.d, n = g.n, N = n + d * n;
  BOXPLUS_CHECK(X.cols() == N && M.rows() == N, "certificate: X must have ", N, " columns");
  CertificateParts p;
  p.XM = g.TimesM(X);
  p.E = p.XM.transpose();
  p.Lambda.resize(n);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(M.nonZeros() + n * d * d);
  for (int k = 0; k < N; ++k) {
    for (SpMat::InnerIterator it(M, k); it; ++it) trip.emplace_back(it.row(), it.col(), it.value());
  }
  for (int i = 0; i < n; ++i) {
    const auto Y = X.middleCols(n + d * i, d);
    const Eigen::MatrixXd L = Y.transpose() * p.XM.middleCols(n + d * i, d);
    p.Lambda[i] = 0.5 * (L + L.transpose());
    p.E.middleRows(n + d * i, d) -= p.Lambda[i] * Y.transpose();
    for (int a = 0; a < d; ++a)
      for (int b = 0; b < d; ++b)
        trip.emplace_back(n + d * i + a, n + d * i + b, -p.Lambda[i](a, b));
  }
  p.S.resize(N, N);
  p.S.setFromTriplets(trip.begin(), trip.end());
  return p;
}

Certificate Certify(const SESyncGraph& g, const SpMat& M, const Eigen::MatrixXd& X,
                    const CertificateOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const int d = g.d, n = g.n, N = n + d * n, r = static_cast<int>(X.rows());
  BOXPLUS_CHECK(r >= d && X.cols() == N && M.rows() == N && M.cols() == N,
                "certificate: X must be r x ", N, " with r >= ", d, " and M ", N, " x ", N);
  BOXPLUS_CHECK(options.relative_tolerance > 0 && std::isfinite(options.relative_tolerance),
                "certificate: relative_tolerance must be positive and finite");
  Certificate c;
  c.rank = r;
  const CertificateParts parts = ComputeCertificateParts(g, M, X);
  const Eigen::MatrixXd& XM = parts.XM;
  c.objective = g.Objective(X);
  // The Riemannian gradient is 2E without the anchor's (held) translation.
  const double grad2 = 4.0 * (parts.E.squaredNorm() - parts.E.row(g.anchor).squaredNorm());
  // f − Σ tr Λᵢ is the translations' part of tr((XM) Xᵀ): zero at a critical
  // point, and computed so, without the cancellation of the difference.
  double gap = 0.0;
  for (int i = 0; i < n; ++i) gap += XM.col(i).dot(X.col(i));
  double max_diag = 0.0;
  for (int k = 0; k < N; ++k) max_diag = std::max(max_diag, std::abs(M.coeff(k, k)));
  c.stationarity = std::sqrt(grad2) / std::max(max_diag * std::max(X.norm(), 1.0), 1e-300);

  // S with the anchor's translation row and column removed (index map).
  std::vector<int> keep(N, -1);
  int m = 0;
  for (int k = 0; k < N; ++k) {
    if (k != g.anchor) keep[k] = m++;
  }
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(parts.S.nonZeros());
  for (int k = 0; k < N; ++k) {
    for (SpMat::InnerIterator it(parts.S, k); it; ++it) {
      const int a = keep[it.row()], b = keep[it.col()];
      if (a >= 0 && b >= 0) trip.emplace_back(a, b, it.value());
    }
  }
  SpMat S(m, m);
  // Not pruned: every diagonal entry stays in the pattern the test analyses.
  S.setFromTriplets(trip.begin(), trip.end());
  Eigen::VectorXd D = Eigen::VectorXd::Zero(m);
  for (int k = n; k < N; ++k) D[keep[k]] = 1.0;

  const double dn = static_cast<double>(d) * n;
  const double target = options.relative_tolerance * std::abs(c.objective);
  c.lambda_min = std::numeric_limits<double>::quiet_NaN();

  // A passed test: S_Q + η·(the identity on `charged` coordinates) ⪰ 0, so by
  // weak duality f − p* ≤ gap + η·charged; certified when that is within the
  // tolerance.
  auto proven = [&](double eta, double charged, const char* test) {
    c.eta = eta;
    c.suboptimality_bound = std::max(gap, 0.0) + eta * charged;
    c.lower_bound = c.objective - c.suboptimality_bound;
    c.certified = c.suboptimality_bound <= target;
    std::ostringstream msg;
    msg << (c.certified ? "certified: the global optimum" : "not certified") << " (" << test
        << ", eta = " << eta << "; f - p* <= " << c.suboptimality_bound << ", relative "
        << c.suboptimality_bound / c.objective << ")";
    if (!c.certified) {
      msg << ": the bound exceeds the tolerance (relative gradient " << c.stationarity
          << "; a point that is not a critical point of SE-Sync's objective needs a solve in the "
             "sesync convention first)";
    }
    c.message = msg.str();
    c.time_s = Seconds(t0);
    return c;
  };

  // The test with the rotation gauge deflated. The rows xₖ of X span S's
  // known near-null space (S xₖ = eₖ, zero at an exact critical point), whose
  // rounding errors a shift η would have to exceed. Remove the anchor's
  // rotation block too: the anchor blocks of the xₖ span Rᵈ, so any v splits
  // as v = w + Σ cₖxₖ with w zero there and ‖c‖ ≤ ‖v_R‖, and
  //   vᵀSv ≥ μ‖w‖² − 2‖E‖‖c‖‖w‖ − ‖XSXᵀ‖‖c‖² ≥ −(‖E‖²/μ + ‖XSXᵀ‖) ‖v_a‖²
  // whenever S'' − μI ≻ 0 (S'' the deflated matrix, E = [eₖ], v_a the
  // anchor's rotation block of v, ‖c‖ = ‖v_a‖). So S_Q + η D_a ⪰ 0 with
  // η = ‖E‖²/μ + ‖XSXᵀ‖ and D_a the anchor block's identity, and weak
  // duality charges η only on that block, whose Z_aa = I_d: f − p* ≤ gap +
  // η d (not η d n). S'' ≻ 0 is robust: its smallest eigenvalue is the
  // graph's connectivity, far above rounding.
  {
    Eigen::MatrixXd Xa(r, m), E(m, r);  // X and E on the kept indices
    for (int k = 0; k < N; ++k) {
      if (keep[k] >= 0) {
        Xa.col(keep[k]) = X.col(k);
        E.row(keep[k]) = parts.E.row(k);
      }
    }
    const double xsx = (Xa * E).norm();
    std::vector<int> keep2(m, -1);
    int m2 = 0;
    for (int k = 0; k < m; ++k) {
      const bool anchor_rotation = k >= keep[n + d * g.anchor] && k < keep[n + d * g.anchor] + d;
      if (!anchor_rotation) keep2[k] = m2++;
    }
    std::vector<Eigen::Triplet<double>> t2;
    t2.reserve(S.nonZeros());
    for (int k = 0; k < m; ++k) {
      for (SpMat::InnerIterator it(S, k); it; ++it) {
        const int a = keep2[it.row()], b = keep2[it.col()];
        if (a >= 0 && b >= 0) t2.emplace_back(a, b, it.value());
      }
    }
    SpMat S2(m2, m2);
    S2.setFromTriplets(t2.begin(), t2.end());
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m2);
    DefinitenessTest deflated(S2, ones);
    const double e2 = E.squaredNorm();
    // μ from 10⁻¹²·max|Sᵢᵢ| up by factors of 10 while S'' − μI stays
    // positive definite and the bound still improves.
    double mu = 1e-12 * max_diag, eta = std::numeric_limits<double>::infinity();
    while (mu < max_diag && deflated.PositiveDefinite(-mu)) {
      eta = e2 / mu + xsx;
      if (std::max(gap, 0.0) + eta * d <= 0.1 * target || e2 / mu < xsx) break;
      mu *= 10.0;
    }
    if (std::isfinite(eta)) return proven(eta, d, "S_Q + eta D_anchor is positive semidefinite");
  }

  // S'' is not positive definite: S has a negative eigenvalue (or the point
  // is far from critical). The plain shifted test, then λ_min by bisection.
  c.eta = std::max(0.5 * target / dn, 1e-12 * max_diag);
  DefinitenessTest test(S, D);
  if (test.PositiveDefinite(c.eta)) return proven(c.eta, dn, "S_Q + eta I is positive definite");

  c.lower_bound = -std::numeric_limits<double>::infinity();
  c.suboptimality_bound = std::numeric_limits<double>::infinity();
  std::ostringstream msg;
  msg << "not certified: S_Q + " << c.eta << " I is not positive definite";
  if (gap > 0.5 * target || c.stationarity > 1e-6) {
    msg << " (the point is not a critical point of SE-Sync's objective: relative gradient "
        << c.stationarity << ")";
  }
  if (options.find_eigenpair) {
    // Bracket λ_min(S_Q) in (lo, hi]: S + (−lo) D ≻ 0 and S + (−hi) D is not.
    double hi = -c.eta, lo = 0.0;
    bool found = false;
    for (double s = 4.0 * c.eta; std::isfinite(s) && s < 1e300; s *= 4.0) {
      if (test.PositiveDefinite(s)) {
        lo = -s;
        found = true;
        break;
      }
      hi = -s;
    }
    if (found) {
      while (hi - lo > 0.01 * std::abs(lo)) {
        const double mid = 0.5 * (lo + hi);
        if (test.PositiveDefinite(-mid)) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      // Inverse iteration on the pencil (S − lo D, D), factorised at lo:
      // converges to the eigenvector of λ_min, which lies within 1 % of lo.
      test.PositiveDefinite(-lo);
      std::mt19937 rng(42);
      std::normal_distribution<double> normal;
      Eigen::VectorXd w(m);
      for (int k = 0; k < m; ++k) w[k] = normal(rng);
      double lambda = hi;
      for (int it = 0; it < 200; ++it) {
        Eigen::VectorXd next = test.Solve(D.cwiseProduct(w));
        const double scale = std::sqrt(next.cwiseProduct(D).dot(next));
        if (!(scale > 0) || !std::isfinite(scale)) break;
        next /= scale;
        const double rq = next.dot(S * next);  // wᵀDw = 1
        w = next;
        const bool done = std::abs(rq - lambda) <= 1e-10 * std::abs(rq);
        lambda = rq;
        if (done) break;
      }
      c.lambda_min = lambda;
      c.eigenvector = Eigen::VectorXd::Zero(N);
      for (int k = 0; k < N; ++k) {
        if (keep[k] >= 0) c.eigenvector[k] = w[keep[k]];
      }
      // Weak duality with η = −λ_min: f − p* ≤ gap + |λ_min| d n.
      c.suboptimality_bound = std::max(gap, 0.0) + std::abs(lambda) * dn;
      c.lower_bound = c.objective - c.suboptimality_bound;
      msg << "; lambda_min(S_Q) = " << lambda << ", f - p* <= " << c.suboptimality_bound;
    }
  }
  c.message = msg.str();
  c.time_s = Seconds(t0);
  return c;
}

}  // namespace boxplus::certify
