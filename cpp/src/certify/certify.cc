#include "boxplus/certify/certify.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "boxplus/errors.h"
#include "newton_polish.h"

namespace boxplus::certify {

using slam::EdgeVerdict;
using slam::OutlierMode;
using slam::OutlierOptions;
using slam::OutlierReport;
using slam::PoseGraph;

namespace {

// Writes X (d × (n + dn), the anchor's translation zero) into the problem's
// values, moved by the rigid transform that takes the anchor's pose in X to
// its current estimate (f is invariant under it), so the held gauge vertex
// keeps its value.
void SetSolution(PoseGraph* pg, const SESyncGraph& sg, const Eigen::MatrixXd& X) {
  const int d = sg.d, n = sg.n;
  const Eigen::MatrixXd current = sg.Stack(pg->graph());  // anchor-relative
  const io::Vertex& anchor = pg->graph().vertices[sg.vertex_of[sg.anchor]];
  Eigen::VectorXd t_anchor = anchor.estimate.head(d);
  const Eigen::MatrixXd G =
      current.middleCols(n + d * sg.anchor, d) * X.middleCols(n + d * sg.anchor, d).transpose();
  const Eigen::MatrixXd moved = G * X;
  io::Graph updated = pg->graph();
  sg.Unstack(moved, t_anchor, &updated);
  for (int i = 0; i < n; ++i) {
    const int v = sg.vertex_of[i];
    const int var = pg->variable_at(v);
    if (!pg->problem().IsFixed(var))
      pg->problem().SetValue(var, updated.vertices[v].estimate.data());
  }
  pg->WriteBack();
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

SolverOptions CertifyLocalSolverOptions() {
  SolverOptions o = slam::DefaultSolverOptions();
  o.max_iterations = 200;
  o.function_tolerance = 1e-15;
  o.gradient_tolerance = 1e-15;
  o.parameter_tolerance = 1e-15;
  return o;
}

CertifyResult CertifyPoseGraph(PoseGraph* pg, const CertifyOptions& options) {
  // After loop closures were judged wrong, the estimate is the optimum of the
  // inliers' graph: that is the problem to certify (the whole graph's
  // optimum is elsewhere), and its estimate is copied back.
  const OutlierReport& judged = pg->outlier_report();
  if (judged.ran && !judged.outliers.empty()) {
    pg->WriteBack();
    io::Graph inliers = pg->graph();
    std::vector<char> wrong(inliers.edges.size(), 0);
    for (const EdgeVerdict& v : judged.outliers) wrong[v.edge] = 1;
    std::vector<io::Edge> kept;
    for (size_t k = 0; k < inliers.edges.size(); ++k) {
      if (!wrong[k]) kept.push_back(std::move(inliers.edges[k]));
    }
    inliers.edges = std::move(kept);
    PoseGraph sub(std::move(inliers), pg->options());
    if (pg->gauge_vertex() >= 0) sub.SetGauge({pg->gauge_vertex()});
    OutlierOptions off = pg->outlier_options();
    off.mode = OutlierMode::kOff;
    sub.set_outlier_options(off);
    CertifyResult r = CertifyPoseGraph(&sub, options);
    for (size_t i = 0; i < pg->graph().vertices.size(); ++i) {
      const int v = static_cast<int>(i);
      if (!pg->problem().IsFixed(pg->variable_at(v))) {
        pg->problem().SetValue(pg->variable_at(v), sub.problem().value(sub.variable_at(v)));
      }
    }
    r.message = "of the inliers' graph (" + std::to_string(judged.outliers.size()) +
                " loop closures judged wrong left out): " + r.message;
    return r;
  }
  const auto t0 = std::chrono::steady_clock::now();
  BOXPLUS_CHECK(pg->options().robust == "none", "certificate: the graph is solved with the robust ",
                "kernel '", pg->options().robust,
                "'; SE-Sync's certificate is for the plain sum of squares (no kernel)");
  int fixed = 0;
  for (size_t v = 0; v < pg->graph().vertices.size(); ++v) {
    fixed += pg->problem().IsFixed(pg->variable_at(static_cast<int>(v)));
  }
  BOXPLUS_CHECK(fixed <= 1, "certificate: ", fixed,
                " vertices are held fixed; SE-Sync's problem holds one pose at most (the gauge)");
  const bool sesync = pg->options().convention == PoseErrorConvention::kSESync;

  CertifyResult out;
  pg->WriteBack();
  const SESyncGraph sg = SESyncGraph::FromGraph(pg->graph(), pg->gauge_vertex());
  const Eigen::SparseMatrix<double> M = sg.DataMatrix();
  Eigen::MatrixXd X = sg.Stack(pg->graph());
  // A rank-d critical point to the accuracy the certificate resolves:
  // Newton steps on SE-Sync's objective (a polish: they move the estimate by
  // about the solver's own tolerance). Another convention's solution is
  // evaluated as it is.
  auto polish = [&] {
    if (internal::NewtonPolish(sg, M, &X) > 0) SetSolution(pg, sg, X);
  };
  if (sesync) polish();
  Certificate cert = Certify(sg, M, X, options.certificate);
  out.verify_time_s += cert.time_s;
  out.max_rank_reached = sg.d;
  double staircase_lower = -std::numeric_limits<double>::infinity();

  // A local solve from the problem's values (unless interrupted), then the
  // polish and the certificate of where it ends.
  auto solve_and_certify = [&] {
    if (!out.interrupted) {
      out.interrupted = pg->Solve(options.local).termination == "interrupted";
    }
    pg->WriteBack();
    X = sg.Stack(pg->graph());
    polish();
    cert = Certify(sg, M, X, options.certificate);
    out.verify_time_s += cert.time_s;
  };
  if (sesync && !cert.certified && cert.stationarity > 1e-10) {
    solve_and_certify();  // far from a critical point: Newton could not polish it
  }
  if (sesync && !cert.certified && !out.interrupted && options.max_rank > sg.d &&
      cert.eigenvector.size() == X.cols()) {
    StaircaseOptions so;
    so.max_rank = options.max_rank;
    so.certificate = options.certificate;
    so.interrupted = options.interrupted;
    const StaircaseResult st = RiemannianStaircase(sg, M, X, cert, so);
    out.staircase_used = true;
    out.max_rank_reached = st.rank;
    out.interrupted = st.interrupted;
    for (const Certificate& c : st.certificates) out.verify_time_s += c.time_s;
    if (st.relaxation_certified) staircase_lower = st.lower_bound;
    const double before = cert.objective;
    SetSolution(pg, sg, st.rounded);
    solve_and_certify();
    out.solution_changed = cert.objective != before;
  }

  out.certificate = cert;
  out.objective = cert.objective;
  out.lower_bound = std::max(cert.lower_bound, staircase_lower);
  // f* ≤ f(x̂) for the feasible x̂ reported, so a bound above f(x̂) by rounding
  // (the relaxation's optimum and the rounded, polished solution agree to
  // ~1e-13 when the relaxation is exact) is f(x̂) itself. A larger excess is
  // left visible: it would be an error, not rounding.
  if (out.lower_bound > out.objective &&
      out.lower_bound - out.objective <= 1e-10 * std::max(1.0, std::abs(out.objective))) {
    out.lower_bound = out.objective;
  }
  out.suboptimality_bound = out.objective - out.lower_bound;
  const double tol = options.certificate.relative_tolerance * std::abs(out.objective);
  out.certified = std::isfinite(out.lower_bound) && out.suboptimality_bound <= tol;
  out.solve_time_s = Seconds(t0) - out.verify_time_s;

  char line[400];
  if (out.certified) {
    std::snprintf(
        line, sizeof line, "certified global optimum: f = %.10g, f - p* <= %.3g (relative %.2g)%s",
        out.objective, out.suboptimality_bound, out.suboptimality_bound / std::abs(out.objective),
        out.staircase_used ? ", found by the Riemannian staircase" : "");
  } else if (std::isfinite(out.lower_bound)) {
    std::snprintf(line, sizeof line,
                  "not certified: f = %.10g, global optimum >= %.10g (f - p* <= %.3g, relative "
                  "%.2g)",
                  out.objective, out.lower_bound, out.suboptimality_bound,
                  out.suboptimality_bound / std::abs(out.objective));
  } else {
    std::snprintf(line, sizeof line, "not certified: f = %.10g, no bound on the global optimum",
                  out.objective);
  }
  out.message = line;
  if (!std::isnan(cert.lambda_min)) {
    std::snprintf(line, sizeof line, "; lambda_min(S) = %.3g", cert.lambda_min);
    out.message += line;
  }
  if (!sesync) {
    out.message += std::string("; evaluated in SE-Sync's objective at the ") +
                   ToString(pg->options().convention) +
                   "-convention solution (solve with the sesync convention to certify)";
  }
  if (out.interrupted) out.message += "; interrupted";
  return out;
}

}  // namespace boxplus::certify
