// Wrong loop closures: graduated non-convexity (GNC) on a pose graph.
//
// A front end's place recognition is never perfect, and one wrong loop closure
// pulls a least-squares trajectory far from the truth; the lowest Σ eᵀΩe is
// then not the trajectory. GNC (Yang, Antonante, Tzoumas, Carlone: "Graduated
// Non-Convexity for Robust Spatial Perception", RA-L 2020) minimises a robust
// cost Σ ρ(eᵀΩe) through a sequence of weighted least-squares problems
// (Black–Rangarajan duality, eq. 5–6): each weight w_k ∈ [0, 1] is the
// minimiser of the outlier process of the surrogate ρ_μ at the current
// residual, and μ moves the surrogate from convex (μ = μ₀) to the robust cost
// itself. In units of the edge's inlier threshold, s = eᵀΩe / c̄², c̄² the
// p-quantile of χ²(d) (d the error's dimension: 3 in 2D, 6 in 3D):
//
//   truncated least squares (TLS, eq. 14; ρ(s) = min(s, 1)):
//     w = 1                    s ≤ μ/(μ+1)
//     w = √(μ(μ+1)/s) − μ      between
//     w = 0                    s ≥ (μ+1)/μ
//     μ₀ = 1 / (2 max s − 1), μ ← 1.4 μ; stop when every weight is 0 or 1.
//     While μ < 0.01, μ ← 1.4 √μ instead (GTSAM's "superlinear" schedule, cut
//     at 0.01): there every closure's weight is ≈ √(μ/s), their ratios
//     barely change, and the linear rounds only cost time. On the generated
//     graphs of bench/bench_outliers.py it took a third to a half of the
//     time and made the same decisions as the linear schedule; continued up
//     to μ = 1 (GTSAM's) it rejected 7 % true closures on clustered outliers.
//   Geman–McClure (GM, eq. 12; ρ(s) = s / (1 + s)):
//     w = (μ / (s + μ))²,  μ₀ = 2 max s, μ ← max(1, μ / 1.4); stop at μ = 1.
// Each round solves the weighted problem warm from the last round (at most
// iterations_per_round iterations); both also stop when the weighted cost
// changes by less than 10⁻⁵ (relative) from one round to the next. Closures
// at weight 0 leave the problem (they only add fill to the factorisation).
//
// GNC graduates from the estimate of the known inliers alone (the odometry
// composed, a spanning tree of them), μ₀ from the residuals there: a start no
// closure pulled. The least-squares solution of all edges is not one: on
// generated graphs with 20 % wrong closures, GNC from the chordal
// relaxation's least-squares solution kept wrong closures and ended at an
// ATE over 20× the inliers' (the start decides which basin GNC ends in).
//
// Which edges are judged: the loop closures. An edge between poses adjacent in
// the file's order (odometry), an edge that is not between two poses (priors,
// landmark observations), and an edge no cycle can check (one the graph needs
// to stay connected once the others are in) are known inliers with weight 1,
// as in GTSAM's GncParams::knownInliers: their error is never compared with
// anything else, and rejecting them would leave poses undetermined.
//
// At the end the closures with eᵀΩe below the χ² quantile at
// keep_probability are the inliers, and the graph is solved once more with
// exactly those (a few passes settle closures near the threshold: gnc.cc):
// the result is the least-squares optimum of the inliers, not a weighted
// compromise.
//
// The thresholds assume the file's information is right. Many files'
// is far too small (parking-garage's 2·10⁴×), and wrong closures then pass
// under them; after a verdict whose inliers' χ²/dof is below half the scale
// the thresholds had, GNC graduates again with c̄² times that χ²/dof
// (PoseGraph::InlierScale, kUnderConfidentScale in pose_graph.h).
//
// eᵀΩe at the inliers' optimum charges a rejected closure with the drift of
// the path between its ends, which the inliers determine loosely on a sparse
// graph: the verdict in the file's units (before its inliers' scale is
// measured) and the final verdict readmit, in stages, the rejected closures
// whose innovation χ² (InnovationChi2 below: the rise of the inliers' χ² if
// it joined them) is within the keep threshold (PoseGraph::Readmit, gnc.cc).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "boxplus/io/g2o.h"

namespace boxplus::slam {

// What PoseGraph::Solve does about wrong loop closures.
//   kAuto  — GNC-TLS when the least-squares solution is implausible
//            (χ²/dof > kImplausibleChi2PerDof), nothing otherwise (the default);
//   kOff   — never: the lowest least-squares minimum (restarts, pose_graph.h);
//   kTls / kGm — GNC with that surrogate, whatever χ²/dof says.
enum class OutlierMode { kAuto, kOff, kTls, kGm };

// "auto", "off" (alias "none"), "gnc-tls" (alias "tls", "gnc"), "gnc-gm"
// (alias "gm"); throws listing them otherwise.
OutlierMode ParseOutlierMode(const std::string& name);
const std::string& OutlierModeName(OutlierMode mode);

struct OutlierOptions {
  OutlierMode mode = OutlierMode::kAuto;
  // c̄² is the quantile of χ²(d) at this probability: an inlier's eᵀΩe is
  // above it with probability 1 − p when the information matrices are right.
  double inlier_probability = 0.99;
  // The verdict at the end keeps a closure whose eᵀΩe is below the quantile
  // at this (higher) probability: a true closure is above c̄² with
  // probability 1 − p, and with 0.99 here too the verdict rejected up to
  // 1.5 % of the true closures of bench/bench_outliers.py's graphs (precision
  // 0.986); with 0.999 it rejected none of them (ATE equal to the inliers'
  // on every quick graph); a wrong closure sits far above either threshold.
  double keep_probability = 0.999;
  // Edges between poses adjacent in the file are known inliers.
  bool odometry_inliers = true;
  // μ's factor per GNC round, and the most rounds.
  double mu_step = 1.4;
  double superlinear_until = 0.01;  // TLS: μ ← mu_step √μ below this
  int max_rounds = 100;
  // Solver iterations per GNC round (warm-started); the final inlier-only
  // solve runs to the caller's convergence criteria.
  int iterations_per_round = 5;
};

// One edge's verdict.
struct EdgeVerdict {
  int edge = -1;  // index in the graph's edges (= its measurement id)
  int line = 0;   // line of the file (0 when added in code)
  int from = -1;  // vertex ids
  int to = -1;
  double weight = 1;  // GNC's last weight
  double chi2 = 0;    // eᵀΩe at the returned estimate
};

struct OutlierReport {
  bool ran = false;                   // GNC ran (mode, or auto on an implausible graph)
  std::string method;                 // "gnc-tls" / "gnc-gm"
  double threshold = 0;               // c̄² of a d = 3 (2D) or 6 (3D) error, × the scale below
  double information_scale = 1;       // < 1: thresholds × the inliers' χ²/dof (pose_graph.h)
  int candidates = 0;                 // loop closures judged
  int rounds = 0;                     // GNC rounds
  std::vector<EdgeVerdict> outliers;  // the rejected edges, in edge order
};

// The report as a text file (boxplus-g2o --outliers): '#' comment lines
// naming the source, the method and the threshold, then one line per edge
// judged wrong: "line from to chi2 weight" (line: of the source file).
std::string FormatOutliers(const OutlierReport& report, const std::string& source);

// The p-quantile of χ²(dof) (bisection on the regularised lower incomplete
// gamma function; exact to 1e-10 relative).
double ChiSquaredQuantile(int dof, double p);

// Innovation χ² of the row blocks `tested` of a least-squares problem,
// against the blocks with in_estimate[k] (block k: rows offsets[k] …
// offsets[k + 1] − 1 of the whitened `jacobian` and `residuals`, evaluated
// at the optimum of the blocks in the estimate):
//   rₖᵀ (I + Aₖ H⁻¹ Aₖᵀ)⁻¹ rₖ,  H = Σ_{in estimate} AⱼᵀAⱼ,
// the rise of the minimum of Σ ‖rⱼ‖² if block k joined (exact for a linear
// problem; the innovation of a Kalman update, Bar-Shalom, Li and
// Kirubarajan 2001, §5.2). NaN for every block when H does not factorise.
std::vector<double> InnovationChi2(const Eigen::SparseMatrix<double>& jacobian,
                                   const Eigen::VectorXd& residuals,
                                   const std::vector<int>& offsets,
                                   const std::vector<char>& in_estimate,
                                   const std::vector<int>& tested);

// The drop of the minimum of Σ ‖rⱼ‖² if block k (in the estimate) left it,
// from the residuals at the minimum with it:
//   rₖᵀ (I − Aₖ H⁻¹ Aₖᵀ)⁻¹ rₖ,  H = Σ_{in estimate} AⱼᵀAⱼ,
// which is block k's innovation χ² against the others (Woodbury: the same
// as rₖᵀ (I + Aₖ H₋ₖ⁻¹ Aₖᵀ) rₖ); a regression's deleted residual (Cook and
// Weisberg, "Residuals and Influence in Regression", 1982, §2.2). NaN for
// every block when H does not factorise.
std::vector<double> DeletionChi2(const Eigen::SparseMatrix<double>& jacobian,
                                 const Eigen::VectorXd& residuals, const std::vector<int>& offsets,
                                 const std::vector<char>& in_estimate,
                                 const std::vector<int>& tested);

// A lower bound on InnovationChi2 of each tested block that is a
// pose-to-pose edge of `graph` (block k = graph.edges[k]), cheap enough to
// screen with: the same expression with H replaced by the information of
// one path of pose-to-pose edges in the estimate between the closure's
// ends (the fewest edges). Marginal covariance only shrinks as
// measurements join, so the path's relative covariance of the ends is at
// least the estimate's. NaN where there is no such path, or a vertex on it
// other than the one it starts from is held fixed (column_of_vertex[v] < 0:
// not among the Jacobian's columns; otherwise its first column, and
// tangent_of_vertex[v] of them).
std::vector<double> InnovationChi2Floor(
    const io::Graph& graph, const std::vector<int>& column_of_vertex,
    const std::vector<int>& tangent_of_vertex, const Eigen::SparseMatrix<double>& jacobian,
    const Eigen::VectorXd& residuals, const std::vector<int>& offsets,
    const std::vector<char>& in_estimate, const std::vector<int>& tested);

// An upper bound on DeletionChi2 of each tested block (pose-to-pose edges
// in the estimate), the same way: rₖᵀ (I + Aₖ P Aₖᵀ) rₖ with P the
// covariance along the fewest-edge path of other pose-to-pose edges in the
// estimate, at least H₋ₖ⁻¹'s. Where that is above enough[i] (when given),
// P from all those edges among the vertices within one edge more of the
// closure's first end than the path's length, when there are at most
// ball_vertices of them (a sparse factorisation of that ball). NaN where
// neither exists.
std::vector<double> DeletionChi2Ceiling(
    const io::Graph& graph, const std::vector<int>& column_of_vertex,
    const std::vector<int>& tangent_of_vertex, const Eigen::SparseMatrix<double>& jacobian,
    const Eigen::VectorXd& residuals, const std::vector<int>& offsets,
    const std::vector<char>& in_estimate, const std::vector<int>& tested,
    const std::vector<double>& enough = {}, size_t ball_vertices = 0);

// TLS / GM weight of a residual s = eᵀΩe / c̄² at control parameter μ.
double TlsWeight(double s, double mu);
double GmWeight(double s, double mu);

}  // namespace boxplus::slam
