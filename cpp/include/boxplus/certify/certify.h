// Certified pose-graph solutions: the pipeline of SE-Sync (Rosen et al., IJRR
// 2019) on a PoseGraph solved in the kSESync convention.
//
//   1. Verify the current solution (certify/certificate.h): one sparse Cholesky
//      factorisation of the certificate; a point that is not yet a critical
//      point of SE-Sync's objective is first solved locally.
//   2. If it is not certified: the Riemannian staircase (certify/staircase.h)
//      from it, rounding the certified relaxation to SO(d)ⁿ, aligned to the
//      gauge pose's estimate.
//   3. A local solve from the rounded point in rank d, and its certificate.
// The reported lower bound on the global optimum p* is the best of the final
// certificate's and the relaxation's (f at a certified rank-r point is a lower
// bound on p*), so a solution that the rank-d test cannot certify still gets
// an upper bound f − p* on its suboptimality where the staircase reached one.
//
// After a Solve that judged loop closures wrong (outlier_rejection.h), the
// certificate is of the inliers' graph, whose optimum the estimate is.
//
// Needs: poses only, relative-pose edges only, no robust loss, at most one
// vertex held fixed (the gauge). For another convention (g2o's, log, ...) the
// certificate is evaluated at the solution as it is (option 1 alone): it
// speaks of SE-Sync's objective, of which that solution is rarely a critical
// point; the report says so.
#pragma once

#include <functional>
#include <string>

#include "boxplus/certify/certificate.h"
#include "boxplus/certify/staircase.h"
#include "boxplus/slam/pose_graph.h"
#include "boxplus/solver_options.h"

namespace boxplus::certify {

// The local solves of steps 1 and 3: the pose-graph default with tolerances
// tight enough for a critical point whose certificate resolves 1e-6·f.
SolverOptions CertifyLocalSolverOptions();

struct CertifyOptions {
  CertificateOptions certificate;
  // Largest rank of the staircase; ≤ d verifies only.
  int max_rank = 10;
  SolverOptions local = CertifyLocalSolverOptions();
  // Polled by the staircase (Ctrl-C); the local solves use local.on_iteration.
  std::function<bool()> interrupted;
};

struct CertifyResult {
  Certificate certificate;   // of the final rank-d point
  bool certified = false;    // f − lower_bound ≤ tolerance · f
  double objective = 0.0;    // f at the final point
  double lower_bound = 0.0;  // on p*: best of the certificate's and the relaxation's
  double suboptimality_bound = 0.0;
  int max_rank_reached = 0;  // d when no staircase was needed
  bool staircase_used = false;
  bool solution_changed = false;  // the staircase moved the estimate
  bool interrupted = false;
  double verify_time_s = 0.0;  // the certificates' time
  double solve_time_s = 0.0;   // local solves and the staircase
  std::string message;         // one line for a person
};

CertifyResult CertifyPoseGraph(slam::PoseGraph* graph, const CertifyOptions& options = {});

}  // namespace boxplus::certify
