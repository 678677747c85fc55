// Bindings of certified pose graphs (boxplus/certify/certify.h): PoseGraph.certify
// and its result, boxplus._core.CertifyResult.
#include <cmath>
#include <cstdio>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/certify/certify.h"
#include "solve_from_python.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterCertify(py::module_& m) {
  using certify::CertifyResult;
  py::class_<CertifyResult>(m, "CertifyResult", R"doc(
What PoseGraph.certify proved (SE-Sync's certificate, docs/guide/certify.md).
``certified``: the solution is the global optimum of SE-Sync's
objective f up to the tolerance (f − f* ≤ tolerance·f proven);
``lower_bound``: a proven lower bound on the global optimum f* (−inf if none);
``suboptimality_bound``: f − lower_bound; ``lambda_min``: the certificate's
smallest eigenvalue when the test failed (NaN when it passed: then it is
> −eta); ``max_rank_reached``: the staircase's highest rank (the graph's
dimension when none was needed); times in seconds.
)doc")
      .def_readonly("certified", &CertifyResult::certified)
      .def_readonly("objective", &CertifyResult::objective)
      .def_readonly("lower_bound", &CertifyResult::lower_bound)
      .def_readonly("suboptimality_bound", &CertifyResult::suboptimality_bound)
      .def_property_readonly("lambda_min",
                             [](const CertifyResult& r) { return r.certificate.lambda_min; })
      .def_property_readonly("eta", [](const CertifyResult& r) { return r.certificate.eta; })
      .def_property_readonly("stationarity",
                             [](const CertifyResult& r) { return r.certificate.stationarity; })
      .def_readonly("max_rank_reached", &CertifyResult::max_rank_reached)
      .def_readonly("staircase_used", &CertifyResult::staircase_used)
      .def_readonly("solution_changed", &CertifyResult::solution_changed)
      .def_readonly("interrupted", &CertifyResult::interrupted)
      .def_readonly("verify_time_s", &CertifyResult::verify_time_s)
      .def_readonly("solve_time_s", &CertifyResult::solve_time_s)
      .def_readonly("message", &CertifyResult::message)
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const CertifyResult& r) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "CertifyResult(certified=%s, objective=%.10g, suboptimality_bound=%.3g, "
                      "max_rank_reached=%d)",
                      r.certified ? "True" : "False", r.objective, r.suboptimality_bound,
                      r.max_rank_reached);
        return std::string(buf);
      });

  auto pose_graph = py::reinterpret_borrow<py::class_<slam::PoseGraph>>(m.attr("PoseGraph"));
  pose_graph.def(
      "certify",
      [](slam::PoseGraph& pg, double tolerance, int max_rank) {
        certify::CertifyOptions co;
        co.certificate.relative_tolerance = tolerance;
        co.max_rank = max_rank;
        CertifyResult result;
        // The one Python solve path: the GIL released, Ctrl-C and Python
        // errors checked between iterations of the local solves and the
        // staircase's ranks.
        SolveFromPython(pg.problem(), py::none(), py::none(), py::kwargs(),
                        [&](const SolverOptions& o) {
                          co.local.on_iteration = o.on_iteration;
                          co.interrupted = [&o] { return !o.on_iteration(IterationInfo()); };
                          result = certify::CertifyPoseGraph(&pg, co);
                          SolveSummary s;
                          s.usable = true;
                          s.termination = result.interrupted ? "interrupted" : "convergence";
                          return s;
                        });
        return result;
      },
      py::arg("tolerance") = 1e-6, py::arg("max_rank") = 10, R"doc(
Proves the current solution globally optimal, or not (SE-Sync's certificate:
one sparse Cholesky factorisation; Rosen et al., IJRR 2019). In the 'sesync'
convention a solution that is not certified is improved by the Riemannian
staircase up to rank ``max_rank`` (the graph's dimension: verify only) and
solved again in place. In other conventions the certificate of SE-Sync's
objective is evaluated at the solution as it is. Returns a CertifyResult.
Raises boxplus.BoxplusError for graphs it does not cover (landmarks, priors,
offsets, a robust kernel, more than one fixed vertex, several components).

Parameters
----------
tolerance : float
    Certify when f − f* ≤ tolerance·f is proven.
max_rank : int
    Highest rank of the Riemannian staircase.
)doc");
}

}  // namespace boxplus::python
