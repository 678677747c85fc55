#include "newton_polish.h"

#include <cmath>
#include <vector>

#include <Eigen/SparseCholesky>

#include "stiefel_manifold.h"

namespace boxplus::certify::internal {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

struct State {
  SpMat S;            // N × N
  Eigen::MatrixXd E;  // S Xᵀ, N × r
  double f = 0.0;
  double e = 0.0;  // ‖E‖ without the anchor's translation row
};

State Measure(const SESyncGraph& g, const SpMat& M, const Eigen::MatrixXd& X) {
  State s;
  CertificateParts parts = ComputeCertificateParts(g, M, X);
  s.S = std::move(parts.S);
  s.E = std::move(parts.E);
  s.f = g.Objective(X);
  s.e = std::sqrt(std::max(0.0, s.E.squaredNorm() - s.E.row(g.anchor).squaredNorm()));
  return s;
}

}  // namespace

int NewtonPolish(const SESyncGraph& g, const SpMat& M, Eigen::MatrixXd* X, int max_steps) {
  const int r = static_cast<int>(X->rows()), d = g.d, n = g.n;
  StiefelManifold stiefel(r, d);
  const int T = stiefel.TangentSize();
  // Coordinates: per pose r translations then T rotation coordinates; the
  // anchor contributes none (its translation is held, its rotation fixes the
  // gauge up to the stabiliser of its block, which the damping absorbs).
  std::vector<int> t_off(n, -1), r_off(n, -1);
  int dim = 0;
  for (int i = 0; i < n; ++i) {
    if (i == g.anchor) continue;
    t_off[i] = dim;
    dim += r;
    r_off[i] = dim;
    dim += T;
  }
  if (dim == 0) return 0;

  State cur = Measure(g, M, *X);
  int kept = 0;
  for (int step = 0; step < max_steps; ++step) {
    std::vector<Eigen::MatrixXd> B(n);  // r·d × T, column-major blocks
    for (int i = 0; i < n; ++i) {
      const Eigen::MatrixXd Y = X->middleCols(n + d * i, d);
      B[i] = stiefel.Basis(Y.data());
    }
    // Row w of coordinate p at slot s of pose i (the slot: 0 translation,
    // 1 + c column c of the rotation block) is e_a for a translation
    // coordinate a, and B_i's rows c·r … c·r + r − 1 of column q for a
    // rotation coordinate q. H_pq = Σ over S's entries of S_kl ⟨w_p, w_q⟩.
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(cur.S.nonZeros() * (T + r));
    auto slot = [&](int k, int* pose) {
      if (k < n) {
        *pose = k;
        return 0;
      }
      *pose = (k - n) / d;
      return 1 + (k - n) % d;
    };
    for (int col = 0; col < cur.S.outerSize(); ++col) {
      int j;
      const int sj = slot(col, &j);
      if (j == g.anchor) continue;
      for (SpMat::InnerIterator it(cur.S, col); it; ++it) {
        int i;
        const int si = slot(static_cast<int>(it.row()), &i);
        if (i == g.anchor) continue;
        const double v = it.value();
        if (si == 0 && sj == 0) {
          for (int a = 0; a < r; ++a) trip.emplace_back(t_off[i] + a, t_off[j] + a, v);
        } else if (si == 0) {
          for (int a = 0; a < r; ++a)
            for (int q = 0; q < T; ++q)
              trip.emplace_back(t_off[i] + a, r_off[j] + q, v * B[j]((sj - 1) * r + a, q));
        } else if (sj == 0) {
          for (int p = 0; p < T; ++p)
            for (int a = 0; a < r; ++a)
              trip.emplace_back(r_off[i] + p, t_off[j] + a, v * B[i]((si - 1) * r + a, p));
        } else {
          const Eigen::MatrixXd W =
              B[i].middleRows((si - 1) * r, r).transpose() * B[j].middleRows((sj - 1) * r, r);
          for (int p = 0; p < T; ++p)
            for (int q = 0; q < T; ++q) trip.emplace_back(r_off[i] + p, r_off[j] + q, v * W(p, q));
        }
      }
    }
    SpMat H(dim, dim);
    H.setFromTriplets(trip.begin(), trip.end());
    double hmax = 0.0;
    for (int k = 0; k < dim; ++k) hmax = std::max(hmax, std::abs(H.coeff(k, k)));
    for (int k = 0; k < dim; ++k) H.coeffRef(k, k) += 1e-12 * hmax;
    Eigen::VectorXd grad(dim);
    for (int i = 0; i < n; ++i) {
      if (i == g.anchor) continue;
      for (int a = 0; a < r; ++a) grad[t_off[i] + a] = cur.E(i, a);
      for (int q = 0; q < T; ++q) {
        double s = 0.0;
        for (int c = 0; c < d; ++c)
          s += B[i].col(q).segment(c * r, r).dot(cur.E.row(n + d * i + c).transpose());
        grad[r_off[i] + q] = s;
      }
    }
    Eigen::SimplicialLDLT<SpMat> ldlt(H);
    if (ldlt.info() != Eigen::Success) break;
    const Eigen::VectorXd z = ldlt.solve(-grad);
    if (!z.allFinite()) break;
    // Backtracking along the Newton step: far from the minimum (a solve that
    // stopped at its iteration limit) the full step can overshoot.
    bool better = false;
    Eigen::MatrixXd next;
    State trial;
    for (double alpha = 1.0; alpha > 1e-3 && !better; alpha *= 0.5) {
      next = *X;
      for (int i = 0; i < n; ++i) {
        if (i == g.anchor) continue;
        next.col(i) += alpha * z.segment(t_off[i], r);
        const Eigen::VectorXd xi = alpha * (B[i] * z.segment(r_off[i], T));
        next.middleCols(n + d * i, d) = OrthonormalFactor(
            X->middleCols(n + d * i, d) + Eigen::Map<const Eigen::MatrixXd>(xi.data(), r, d));
      }
      trial = Measure(g, M, next);
      better = trial.e < cur.e && trial.f <= cur.f + 1e-12 * std::abs(cur.f);
    }
    if (!better) break;
    *X = next;
    ++kept;
    const bool converged = trial.e > 0.5 * cur.e && trial.f >= cur.f - 1e-14 * std::abs(cur.f);
    cur = std::move(trial);
    if (converged) break;
  }
  return kept;
}

}  // namespace boxplus::certify::internal
