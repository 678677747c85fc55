// Bindings of boxplus::Problem: variables, solving (with the GIL
// released, Ctrl-C honoured between iterations), covariances.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "boxplus/manifolds.h"
#include "boxplus/problem.h"
#include "manifold_handle.h"
#include "pending_error.h"
#include "python_manifold.h"
#include "solve_from_python.h"
#include "solver.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
// Problem.set_value: size and Python manifold checked before the C++ problem
// (which normalises unit parts) stores it.
void SetValue(Problem& p, int id, const Eigen::VectorXd& v) {
  if (v.size() != p.manifold(id).AmbientSize()) {
    throw py::value_error("set_value: wrong size for variable '" + p.variable_name(id) + "'");
  }
  if (auto* pm = dynamic_cast<const PythonManifold*>(&p.manifold(id))) {
    pm->Validate(v.data(), VariableWhat(p, id));
  }
  p.SetValue(id, v.data());
}

// The value of kind T whose ambient vector is `a` bit for bit, for copies of
// a problem (pickling): the public constructors normalise unit quaternions
// and directions, and normalising a stored value again can move its last bit.
// `a` must be a valid value already (within rounding of the normalised one).
template <class T>
py::object ExactValue(const Eigen::VectorXd& a, const std::string& kind) {
  if (a.size() != T::kAmbient) {
    throw py::value_error(kind + ": " + std::to_string(a.size()) + " numbers for an ambient size " +
                          std::to_string(T::kAmbient));
  }
  const T t = FromAmbientExactly<T>(a);
  if ((Eigen::Map<const Eigen::VectorXd>(t.data(), a.size()) - a).cwiseAbs().maxCoeff() > 0) {
    throw py::value_error(kind + ": the ambient vector is not a normalised value");
  }
  return py::cast(t);
}

// The repr: "<boxplus.Problem: N variables (k fixed, d free tangent
// dimensions), M measurements (r residuals)>".
std::string DescribeProblem(const Problem& p) {
  int fixed = 0, free_dims = 0, residuals = 0;
  for (int id = 0; id < p.num_variables(); ++id) {
    if (p.IsFixed(id)) {
      ++fixed;
    } else {
      free_dims += p.manifold(id).TangentSize();
    }
  }
  for (int id = 0; id < p.num_measurements(); ++id) residuals += p.residual_size(id);
  return "<boxplus.Problem: " + std::to_string(p.num_variables()) + " variables (" +
         std::to_string(fixed) + " fixed, " + std::to_string(free_dims) +
         " free tangent dimensions), " + std::to_string(p.num_measurements()) + " measurements (" +
         std::to_string(residuals) + " residuals)>";
}

}  // namespace

void RegisterProblem(py::module_& m) {
  m.def(
      "exact_value",
      [](const std::string& kind, const Eigen::VectorXd& a) {
        if (kind == "SO3") return ExactValue<SO3>(a, kind);
        if (kind == "SE3") return ExactValue<SE3>(a, kind);
        if (kind == "S2") return ExactValue<S2>(a, kind);
        throw py::value_error("exact_value: kind must be SO3, SE3 or S2, got '" + kind + "'");
      },
      py::arg("kind"), py::arg("ambient"),
      "The SO3, SE3 or S2 value with exactly these ambient numbers (from_ambient "
      "normalises again, which can move the last bit); for copies of a problem.");
  py::class_<UndeterminedVariable>(m, "UndeterminedVariable",
                                   "The tangent directions of one variable the data leave free.")
      .def_readonly("variable", &UndeterminedVariable::variable)
      .def_readonly("directions", &UndeterminedVariable::directions,
                    "Orthonormal columns in the variable's tangent coordinates.")
      .def_readonly("moves_with", &UndeterminedVariable::moves_with,
                    "The variables these directions are tied to (a shared null vector).")
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const UndeterminedVariable& u) {
        return "<UndeterminedVariable " + std::to_string(u.variable) + ": " +
               std::to_string(u.directions.cols()) + " free direction(s)>";
      });
  py::class_<Determinedness>(m, "Determinedness", R"doc(
The rank test of a problem's Jacobian at its current values.

Columns are equilibrated (J D⁻¹), and a direction counts as undetermined when
its singular value is below ``tolerance`` times the largest; see
``boxplus/determinedness.h`` for the method.)doc")
      .def_readonly("num_columns", &Determinedness::num_columns)
      .def_readonly("rank", &Determinedness::rank)
      .def_readonly("largest_singular_value", &Determinedness::largest_singular_value)
      .def_readonly("tolerance", &Determinedness::tolerance)
      .def_readonly("variables", &Determinedness::variables)
      .def_readonly("column_offsets", &Determinedness::column_offsets)
      .def_readonly("null_space", &Determinedness::null_space,
                    "Orthonormal basis of the null space in equilibrated coordinates.")
      .def_readonly("column_norms", &Determinedness::column_norms)
      .def_readonly("undetermined", &Determinedness::undetermined)
      .def_property_readonly("determined", &Determinedness::determined)
      .def_property_readonly("nullity", &Determinedness::nullity)
      .def("todict", &PropertiesToDict, kToDictDoc)
      .def("__repr__", [](const Determinedness& d) {
        return "<Determinedness rank " + std::to_string(d.rank) + " of " +
               std::to_string(d.num_columns) + ">";
      });

  py::class_<Problem>(m, "Problem", R"doc(
The C++ least-squares problem: variables on manifolds and whitened residuals.
The public, friendlier front is boxplus.OptimizationProblem.
)doc")
      .def(py::init<>())
      .def("__repr__", &DescribeProblem)
      .def(
          "add_variable",
          [](Problem& p, const ManifoldHandle& m, const Eigen::VectorXd& init,
             const std::string& name) {
            if (init.size() != m.manifold->AmbientSize()) {
              throw py::value_error("variable '" + name + "': initial value has " +
                                    std::to_string(init.size()) + " entries, the " + m.kind +
                                    " manifold " + std::to_string(m.manifold->AmbientSize()));
            }
            if (auto* pm = dynamic_cast<const PythonManifold*>(m.manifold.get())) {
              pm->Validate(init.data(), "variable '" + name + "'");
            }
            return p.AddVariable(m.manifold, init.data(), name);
          },
          py::arg("manifold"), py::arg("init"), py::arg("name") = "")
      .def_property_readonly("num_variables", &Problem::num_variables)
      .def_property_readonly("generation", &Problem::generation,
                             "Changes whenever values, fixed flags, variables or measurements "
                             "change (a cache key for results of the current state).")
      .def_property_readonly("num_measurements", &Problem::num_measurements)
      .def(
          "value",
          [](const Problem& p, int id) {
            const int n = p.manifold(id).AmbientSize();
            return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(p.value(id), n));
          },
          py::arg("id"), "Copy of the variable's ambient vector.")
      .def("set_value", &SetValue, py::arg("id"), py::arg("value"))
      .def(
          "restore_value",
          [](Problem& p, int id, const Eigen::VectorXd& v) {
            SetValue(p, id, v);  // validates, holds the problem, normalises
            // A stored value was normalised already; normalising it again can move
            // its last bits, so a copy (pickling) puts back the exact bits when
            // they differ from the normalised ones by rounding only.
            double* stored = const_cast<double*>(p.value(id));
            const int n = static_cast<int>(v.size());
            if ((Eigen::Map<const Eigen::VectorXd>(stored, n) - v).cwiseAbs().maxCoeff() <= 1e-12) {
              std::copy(v.data(), v.data() + n, stored);
            }
          },
          py::arg("id"), py::arg("value"),
          "set_value for a value read with value(id): the same bits back (for copies).")
      .def("variable_name", &Problem::variable_name, py::arg("id"))
      .def("measurement_name", &Problem::measurement_name, py::arg("id"))
      .def("measurement_variables", &Problem::measurement_variables, py::arg("id"))
      .def("set_fixed", &Problem::SetFixed, py::arg("id"), py::arg("fixed") = true)
      .def("is_fixed", &Problem::IsFixed, py::arg("id"))
      .def("noise", &Problem::noise, py::arg("measurement_id"),
           "The noise model a measurement whitens with.")
      .def(
          "error", [](Problem& p, int id) { return RaisingPython([&] { return p.Error(id); }); },
          py::arg("measurement_id"),
          "Un-whitened error e = W⁻¹ r of one measurement, in its own units.")
      .def(
          "solve",
          [](Problem& p, const py::object& options, const py::object& callback,
             const py::kwargs& overrides) {
            return SolveFromPython(p, options, callback, overrides,
                                   [&p](const SolverOptions& o) { return p.Solve(o); });
          },
          py::arg("options") = py::none(), py::arg("callback") = py::none(),
          R"doc(
Minimises ½ Σ ρ(‖rᵢ‖²) with ⊞ steps.

Parameters
----------
options : SolverOptions, optional
    The settings (default: SolverOptions()).
callback : callable, optional
    ``callback(info: IterationInfo)`` after each iteration; return False to
    stop (None or True continue). Ctrl-C stops the solve and keeps the last
    accepted estimate (termination 'interrupted').
**overrides
    Fields of SolverOptions that replace those of ``options``
    (``nonmonotonic_steps=n`` sets both nonmonotonic fields).

Returns
-------
SolveSummary
    Raises the Python exception of a failing measurement function, manifold
    or callback, with its traceback.
)doc")
      .def(
          "cost", [](Problem& p) { return RaisingPython([&] { return p.Cost(); }); },
          "½ Σ ρ(‖rᵢ‖²) at the current values.")
      .def(
          "residual",
          [](Problem& p, int id) { return RaisingPython([&] { return p.Residual(id); }); },
          py::arg("measurement_id"), "Whitened residual of one measurement.")
      .def(
          "covariance",
          [](Problem& p, int id) { return RaisingPython([&] { return p.Covariance(id); }); },
          py::arg("id"), "Marginal covariance in the variable's tangent space.")
      .def(
          "joint_covariance",
          [](Problem& p, const std::vector<int>& ids) {
            return RaisingPython([&] { return p.JointCovariance(ids); });
          },
          py::arg("ids"))
      .def("set_direction_labels", &Problem::SetDirectionLabels, py::arg("id"), py::arg("labels"),
           "Names of the variable's tangent directions, used when a message names an "
           "undetermined direction.")
      .def(
          "check_determined",
          [](Problem& p, double relative_tolerance, double support_tolerance) {
            DeterminednessOptions o;
            o.relative_tolerance = relative_tolerance;
            o.support_tolerance = support_tolerance;
            return RaisingPython([&] { return p.CheckDetermined(o); });
          },
          py::arg("relative_tolerance") = DeterminednessOptions().relative_tolerance,
          py::arg("support_tolerance") = DeterminednessOptions().support_tolerance,
          "The rank test of the Jacobian at the current values (kept until the problem or "
          "its values change): which tangent directions the measurements leave free.")
      .def(
          "describe_undetermined",
          [](Problem& p, const Determinedness& d) {
            return DescribeUndetermined(
                d, [&p](int v) { return p.variable_name(v); },
                [&p](int v) { return p.direction_labels(v); });
          },
          py::arg("determinedness"),
          "\"'b': x, y (tied to 'a'); ...\": the undetermined variables and their free "
          "directions, named with the variables' direction labels.")
      .def(
          "normal_matrix",
          [](Problem& p) {
            SparseJacobianEvaluation e = RaisingPython([&] { return p.EvaluateSparseJacobian(); });
            py::dict d;
            const Eigen::SparseMatrix<double> h = e.jacobian.transpose() * e.jacobian;
            d["normal_matrix"] = Eigen::MatrixXd(h);
            d["residuals"] = e.residuals;
            d["variables"] = e.variables;
            d["column_offsets"] = e.column_offsets;
            return d;
          },
          "JᵀJ of the whitened Jacobian (dense n × n, formed from the sparse J) in the "
          "tangent spaces of the free variables: a dict with normal_matrix, residuals "
          "(whitened, as evaluate_jacobian's), variables (free ids) and column_offsets.")
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
