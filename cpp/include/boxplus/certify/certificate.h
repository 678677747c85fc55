// Certifying a pose graph's solution as the global optimum (SE-Sync: Rosen,
// Carlone, Bandeira, Leonard, "SE-Sync: A certifiably correct algorithm for
// synchronization over the special Euclidean group", IJRR 38(2–3), 2019).
//
// The objective is SE-Sync's (Eq. 10; the kSESync convention, factors/pose/
// chordal_relative_pose.h), over the pose–pose edges (i, j) of the graph:
//   f(t, R) = Σ κᵢⱼ‖Rⱼ − RᵢR̃ᵢⱼ‖²_F + τᵢⱼ‖tⱼ − tᵢ − Rᵢt̃ᵢⱼ‖².
// Stacking X = [t₁ … tₙ | R₁ … Rₙ] ∈ R^{r×(n+dn)} (r = d for poses; r > d for
// the rank-r relaxation of the Riemannian staircase, whose rotation blocks
// Yᵢ ∈ St(d, r) have orthonormal columns), f = tr(X M Xᵀ) with the sparse
// data matrix M = Σ κ B Bᵀ + τ b bᵀ, where X B = Rⱼ − RᵢR̃ᵢⱼ and
// X b = tⱼ − tᵢ − Rᵢt̃ᵢⱼ (Eq. 13–15 with the translations kept).
//
// At a first-order critical point the multipliers are (Eq. 25)
//   Λᵢ = Sym(Yᵢᵀ (X M)_{Rᵢ}),   S = M − Diag(0, Λ₁, …, Λₙ)   (Eq. 26),
// and S ⪰ 0 proves the point globally optimal for the semidefinite
// relaxation, hence for the pose graph when r = d (Theorem 7). Translations
// are eliminated exactly by a Schur complement: with one translation
// anchored (f is invariant to a common shift), the translation block L_τ of
// S is positive definite, so
//   S_anch + η·Diag(0, I) ≻ 0   ⟺   S_Q + η I ≻ 0,
// S_Q = the certificate of the reduced problem in rotations alone (Eq. 20).
// That test is one sparse Cholesky factorisation (Rosen, "Accelerating
// certifiable estimation with preconditioned eigensolvers", RA-L 2022,
// proposes it in place of an eigensolver). Weak duality then bounds the
// suboptimality by
//   f(X) − p* ≤ f(X) − Σ tr Λᵢ + η d n,
// which is what `suboptimality_bound` reports: the gap term is zero at an
// exact critical point, η·d·n the price of the tolerance. Rounding makes S's
// known null space (the rows of X) slightly indefinite, so the test first
// deflates it: with the anchor's rotation block removed too, S'' is positive
// definite by a margin μ (the graph's connectivity) at a certifiable point,
// and the residual E = S Xᵀ (half the Riemannian gradient) enters as
// η = ‖E‖²/μ + ‖XSXᵀ‖ on the anchor's block alone: f − p* ≤ gap + η d
// (certificate.cc derives it). Only when S'' is not positive definite is
// S + η·Diag(0, I) tested (η = tolerance·f / 2dn, floored at 10⁻¹²·max Mᵢᵢ),
// and then λ_min(S_Q) is bracketed by bisection on the shift (each step a
// Cholesky test) and its eigenvector found by inverse
// iteration on the pencil (S_anch − σ Diag(0, I)): the direction the
// staircase escapes along (Sec. 4.1.2).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "boxplus/io/g2o.h"

namespace boxplus::certify {

struct CertificateOptions {
  // Certify when the bound on f − p* is at most this fraction of f.
  double relative_tolerance = 1e-6;
  // Whether to find λ_min(S_Q) and its eigenvector when the test fails
  // (bisection and inverse iteration: tens of factorisations).
  bool find_eigenpair = true;
};

struct Certificate {
  bool certified = false;
  int rank = 0;                      // r of the point tested
  double objective = 0.0;            // f at the point, SE-Sync's objective
  double lower_bound = 0.0;          // on the global optimum p* (−inf if none)
  double suboptimality_bound = 0.0;  // f − lower_bound (inf if none)
  double eta = 0.0;                  // the shift tested: S_Q + ηI ≻ 0?
  // λ_min(S_Q) when the test failed and find_eigenpair (bracketed to 1 %),
  // else NaN: known only to be > −η.
  double lambda_min = 0.0;
  // ‖grad f‖ / ‖M‖ at the point (Riemannian): small at a critical point.
  double stationarity = 0.0;
  double time_s = 0.0;
  std::string message;
  // The eigenvector of λ_min in the order of X's columns (translations,
  // then rotations), when found; the staircase's escape direction.
  Eigen::VectorXd eigenvector;
};

// The pose–pose edges of a graph in SE-Sync's form. Throws boxplus::Error
// naming the first edge (and line) the certificate does not cover: anything
// but EDGE_SE2/EDGE_SE3:QUAT (and their TORO and EQUIV forms).
struct SESyncGraph {
  struct Edge {
    int i = 0, j = 0;   // pose indices (0 … n−1)
    Eigen::MatrixXd R;  // R̃ᵢⱼ, d × d
    Eigen::VectorXd t;  // t̃ᵢⱼ
    double kappa = 0.0, tau = 0.0;
  };
  int d = 0;                   // 2 or 3
  int n = 0;                   // poses
  int anchor = 0;              // the pose whose translation is held
  std::vector<int> vertex_of;  // pose index → index in io::Graph::vertices
  std::vector<Edge> edges;

  // anchor_id: the vertex id held for the gauge (−1: the first pose).
  static SESyncGraph FromGraph(const io::Graph& graph, int anchor_id = -1);
  // M, size n + d n (translations first).
  Eigen::SparseMatrix<double> DataMatrix() const;
  // X M and f(X) = tr(X M Xᵀ), accumulated edge by edge from the residuals
  // Rⱼ − RᵢR̃ᵢⱼ and tⱼ − tᵢ − Rᵢt̃ᵢⱼ: the products X·M and (XM)·X cancel
  // terms of size τ‖t‖² down to f, losing digits that the certificate needs
  // (on parking-garage 10⁸ against f ≈ 1.26).
  Eigen::MatrixXd TimesM(const Eigen::MatrixXd& X) const;
  double Objective(const Eigen::MatrixXd& X) const;
  // X (d × (n + dn)) of the graph's vertex estimates, translations shifted
  // so that the anchor's is zero.
  Eigen::MatrixXd Stack(const io::Graph& graph) const;
  // Writes X (rank d) back into the graph's estimates, the anchor's
  // translation restored to `anchor_translation`.
  void Unstack(const Eigen::MatrixXd& X, const Eigen::VectorXd& anchor_translation,
               io::Graph* graph) const;
};

// f(X) = tr(X M Xᵀ).
double SESyncObjective(const Eigen::SparseMatrix<double>& M, const Eigen::MatrixXd& X);

// What the certificate and the Newton polish need at X, computed once:
// X M (edge by edge), the multipliers Λᵢ = Sym(Yᵢᵀ (XM)_{Rᵢ}) (Eq. 25),
// S = M − Diag(0, Λ₁, …, Λₙ) (N × N, translations first) and the residual
// E = S Xᵀ = (XM)ᵀ − Diag(0, Λ) Xᵀ (N × r, half the Riemannian gradient),
// formed from XM rather than as S·Xᵀ, which would cancel large terms.
struct CertificateParts {
  Eigen::MatrixXd XM;
  std::vector<Eigen::MatrixXd> Lambda;
  Eigen::SparseMatrix<double> S;
  Eigen::MatrixXd E;
};
CertificateParts ComputeCertificateParts(const SESyncGraph& graph,
                                         const Eigen::SparseMatrix<double>& M,
                                         const Eigen::MatrixXd& X);

// The certificate of X (rank r ≥ d, rotation blocks with orthonormal columns)
// for the data matrix M of `graph`.
Certificate Certify(const SESyncGraph& graph, const Eigen::SparseMatrix<double>& M,
                    const Eigen::MatrixXd& X, const CertificateOptions& options = {});

}  // namespace boxplus::certify
