// Bindings of boxplus::Problem: variables, priors, solving (with the GIL
// released, Ctrl-C honoured between iterations), covariances.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/factors/make_prior.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"
#include "pending_error.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

Method ParseMethod(const std::string& name) {
  if (name == "lm" || name == "levenberg_marquardt") return Method::kLevenbergMarquardt;
  if (name == "gn" || name == "gauss_newton") return Method::kGaussNewton;
  if (name == "dogleg") return Method::kDogleg;
  if (name == "gn_ls" || name == "gn-ls") return Method::kGaussNewtonLineSearch;
  throw py::value_error("unknown method '" + name +
                        "' (expected 'lm', 'gn', 'gn_ls' or 'dogleg')");
}

py::dict InfoToDict(const IterationInfo& i) {
  py::dict d;
  d["iteration"] = i.iteration;
  d["cost"] = i.cost;
  d["cost_change"] = i.cost_change;
  d["gradient_max_norm"] = i.gradient_max_norm;
  d["step_norm"] = i.step_norm;
  d["trust_region_radius"] = i.trust_region_radius;
  d["iteration_time_s"] = i.iteration_time_s;
  d["cumulative_time_s"] = i.cumulative_time_s;
  d["step_is_successful"] = i.step_is_successful;
  return d;
}

// Runs f; if a Python callback failed inside it, raises that error instead
// of the generic C++ one.
template <class F>
auto RaisingPython(F f) {
  TakePendingError();
  try {
    return f();
  } catch (const std::exception&) {
    if (auto e = TakePendingError()) throw std::move(*e);
    throw;
  }
}

}  // namespace

void RegisterProblem(py::module_& m) {
  py::class_<SolveSummary>(m, "SolveSummary", "What a solve did and why it stopped.")
      .def_readonly("initial_cost", &SolveSummary::initial_cost, "½‖F(X₀)‖²")
      .def_readonly("final_cost", &SolveSummary::final_cost, "½‖F(X)‖² at the estimate")
      .def_readonly("iterations", &SolveSummary::iterations)
      .def_readonly("time_s", &SolveSummary::time_s)
      .def_readonly("termination", &SolveSummary::termination,
                    "'convergence', 'no_convergence', 'interrupted' or 'failure'")
      .def_readonly("message", &SolveSummary::message)
      .def_readonly("usable", &SolveSummary::usable)
      .def_readonly("report", &SolveSummary::report, "Ceres' full report.")
      .def("__repr__", [](const SolveSummary& s) {
        return "<SolveSummary " + s.termination + ": cost " + std::to_string(s.initial_cost) +
               " -> " + std::to_string(s.final_cost) + " in " + std::to_string(s.iterations) +
               " iterations, " + std::to_string(s.time_s) + " s>";
      });

  py::class_<Problem>(m, "Problem", R"doc(
The C++ least-squares problem: variables on manifolds and whitened residuals.
The public, friendlier front is boxplus.OptimizationProblem.
)doc")
      .def(py::init<>())
      .def(
          "add_variable",
          [](Problem& p, const ManifoldHandle& m, const Eigen::VectorXd& init,
             const std::string& name) {
            if (init.size() != m.manifold->AmbientSize()) {
              throw py::value_error("variable '" + name + "': initial value has " +
                                    std::to_string(init.size()) + " entries, the " + m.kind +
                                    " manifold " + std::to_string(m.manifold->AmbientSize()));
            }
            return p.AddVariable(m.manifold, init.data(), name);
          },
          py::arg("manifold"), py::arg("init"), py::arg("name") = "")
      .def_property_readonly("num_variables", &Problem::num_variables)
      .def_property_readonly("num_measurements", &Problem::num_measurements)
      .def(
          "value", [](const Problem& p, int id) {
            const int n = p.manifold(id).AmbientSize();
            return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(p.value(id), n));
          },
          py::arg("id"), "Copy of the variable's ambient vector.")
      .def(
          "set_value",
          [](Problem& p, int id, const Eigen::VectorXd& v) {
            if (v.size() != p.manifold(id).AmbientSize()) {
              throw py::value_error("set_value: wrong size for variable '" + p.variable_name(id) + "'");
            }
            p.SetValue(id, v.data());
          },
          py::arg("id"), py::arg("value"))
      .def("variable_name", &Problem::variable_name, py::arg("id"))
      .def("measurement_name", &Problem::measurement_name, py::arg("id"))
      .def("measurement_variables", &Problem::measurement_variables, py::arg("id"))
      .def("set_fixed", &Problem::SetFixed, py::arg("id"), py::arg("fixed") = true)
      .def("is_fixed", &Problem::IsFixed, py::arg("id"))
      .def(
          "add_prior",
          [](Problem& p, int id, const Eigen::VectorXd& z, const NoiseModel& noise,
             const std::string& name, const LossHandle* loss) {
            const std::string what = "measurement '" + (name.empty() ? std::string("prior") : name) + "'";
            return p.AddMeasurement(MakePrior(p.manifold(id), z, noise, what), {id}, noise,
                                    loss ? loss->loss : nullptr, name);
          },
          py::arg("id"), py::arg("z"), py::arg("noise"), py::arg("name") = "",
          py::arg("loss") = nullptr,
          "Adds r = W (x ⊟ z) on variable id; z in ambient coordinates, W the noise's whitening.")
      .def("noise", &Problem::noise, py::arg("measurement_id"),
           "The noise model a measurement whitens with.")
      .def("error",
           [](Problem& p, int id) { return RaisingPython([&] { return p.Error(id); }); },
           py::arg("measurement_id"),
           "Un-whitened error e = W⁻¹ r of one measurement, in its own units.")
      .def(
          "solve",
          [](Problem& p, const std::string& method, int max_iterations, double function_tolerance,
             double gradient_tolerance, double parameter_tolerance, int num_threads, bool verbose,
             const py::object& callback, double initial_trust_region_radius,
             const std::string& damping, bool jacobi_scaling, int nonmonotonic_steps) {
            SolverOptions o;
            o.method = ParseMethod(method);
            if (!(initial_trust_region_radius > 0)) {
              throw py::value_error("initial_trust_region_radius must be > 0");
            }
            o.initial_trust_region_radius = initial_trust_region_radius;
            if (damping == "marquardt") {
              o.damping = Damping::kMarquardt;
            } else if (damping == "levenberg") {
              o.damping = Damping::kLevenberg;
            } else {
              throw py::value_error("unknown damping '" + damping +
                                    "' (expected 'marquardt' or 'levenberg')");
            }
            o.jacobi_scaling = jacobi_scaling;
            if (nonmonotonic_steps < 0) throw py::value_error("nonmonotonic_steps must be >= 0");
            o.use_nonmonotonic_steps = nonmonotonic_steps > 0;
            o.max_consecutive_nonmonotonic_steps = nonmonotonic_steps;
            o.max_iterations = max_iterations;
            o.function_tolerance = function_tolerance;
            o.gradient_tolerance = gradient_tolerance;
            o.parameter_tolerance = parameter_tolerance;
            o.num_threads = num_threads;
            o.verbose = verbose;
            // Python errors raised in the callback are kept and re-raised
            // after Ceres has returned; Ctrl-C only stops the solve.
            std::unique_ptr<py::error_already_set> pending;
            TakePendingError();  // a stale error from an earlier evaluation
            o.on_iteration = [&](const IterationInfo& info) {
              py::gil_scoped_acquire gil;
              if (HasPendingError()) return false;
              if (PyErr_CheckSignals() != 0) {
                if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {
                  PyErr_Clear();
                  return false;
                }
                pending = std::make_unique<py::error_already_set>();
                return false;
              }
              if (!callback.is_none()) {
                try {
                  py::object r = callback(InfoToDict(info));
                  if (!r.is_none() && !r.cast<bool>()) return false;
                } catch (py::error_already_set& e) {
                  pending = std::make_unique<py::error_already_set>(std::move(e));
                  return false;
                }
              }
              return true;
            };
            SolveSummary s;
            {
              py::gil_scoped_release release;
              s = p.Solve(o);
            }
            if (!pending) pending = TakePendingError();
            if (pending && pending->matches(PyExc_KeyboardInterrupt)) {
              // Ctrl-C inside a Python measurement: keep the estimate.
              s.termination = "interrupted";
              s.usable = true;
              pending.reset();
            }
            if (pending) throw std::move(*pending);
            return s;
          },
          py::arg("method") = "lm", py::arg("max_iterations") = 100,
          py::arg("function_tolerance") = 1e-10, py::arg("gradient_tolerance") = 1e-12,
          py::arg("parameter_tolerance") = 1e-10, py::arg("num_threads") = 1,
          py::arg("verbose") = false, py::arg("callback") = py::none(),
          py::arg("initial_trust_region_radius") = 1e4, py::arg("damping") = "marquardt",
          py::arg("jacobi_scaling") = true, py::arg("nonmonotonic_steps") = 0,
          R"doc(
Minimises ½ Σ ρ(‖rᵢ‖²) with ⊞ steps.

Parameters
----------
method : {'lm', 'gn', 'gn_ls', 'dogleg'}
    Levenberg–Marquardt, Gauss–Newton (undamped, steps that raise the cost are
    rejected), Gauss–Newton with a backtracking line search (boxplus' own:
    single-threaded, robust losses by reweighting; the trust-region options do
    not apply), or Powell's dogleg.
initial_trust_region_radius : float
    Ceres' initial radius μ₀ (LM solves (JᵀJ + D/μ) δ = −Jᵀr); a huge value
    (1e16) starts like Gauss–Newton and damps only after a failed step.
damping : {'marquardt', 'levenberg'}
    D = diag(JᵀJ) (Ceres' default) or D = I (λI, as g2o's LM).
jacobi_scaling : bool
    Scale the columns of J by 1/(1 + ‖J_k‖) before solving (Ceres' default).
nonmonotonic_steps : int
    Accept up to this many consecutive cost increases while the best cost
    still decreases (0: monotonic).
callback : callable, optional
    Called after each iteration with a dict (iteration, cost, ...); return
    False to stop. Ctrl-C stops the solve and keeps the last accepted estimate
    (termination 'interrupted').
)doc")
      .def("cost", [](Problem& p) { return RaisingPython([&] { return p.Cost(); }); },
           "½ Σ ρ(‖rᵢ‖²) at the current values.")
      .def("residual",
           [](Problem& p, int id) { return RaisingPython([&] { return p.Residual(id); }); },
           py::arg("measurement_id"), "Whitened residual of one measurement.")
      .def("covariance", &Problem::Covariance, py::arg("id"),
           "Marginal covariance in the variable's tangent space.")
      .def("joint_covariance", &Problem::JointCovariance, py::arg("ids"))
      .def(
          "evaluate_jacobian",
          [](Problem& p) {
            JacobianEvaluation e = RaisingPython([&] { return p.EvaluateJacobian(); });
            py::dict d;
            d["residuals"] = e.residuals;
            d["jacobian"] = e.jacobian;
            d["variables"] = e.variables;
            d["column_offsets"] = e.column_offsets;
            d["row_offsets"] = e.row_offsets;
            return d;
          },
          "Whitened residuals and their dense Jacobian in the tangent spaces of the free "
          "variables: a dict with residuals (m,), jacobian (m, n), variables (free ids), "
          "column_offsets, row_offsets (per measurement).");
}

}  // namespace boxplus::python
