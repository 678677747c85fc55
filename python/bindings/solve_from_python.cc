#include "solve_from_python.h"

#include <memory>
#include <string>

#include "boxplus/progress.h"
#include "pending_error.h"
#include "python_manifold.h"
#include "solver.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

// Raises, before Ceres sees it, the error a Python manifold's ⊞ would give
// at variable id's current value (a failing ⊞ inside Ceres would abort).
void ValidatePythonManifold(const Problem& p, int id, const std::string& what) {
  if (const auto* pm = dynamic_cast<const PythonManifold*>(&p.manifold(id))) {
    pm->Validate(p.value(id), what);
  }
}

// Whether a callback's return value asks to stop; None and booleans only.
bool CallbackContinues(const py::object& r) {
  if (r.is_none()) return true;
  const std::string type = py::str(py::type::of(r).attr("__name__"));
  if (py::isinstance<py::bool_>(r) || type == "bool_" || type == "bool")
    return r.cast<bool>();  // numpy bools too
  throw py::type_error("the solve callback must return None, True or False, got " + type + " " +
                       std::string(py::repr(r)).substr(0, 80));
}

}  // namespace

std::string VariableWhat(const Problem& p, int id) {
  const std::string& name = p.variable_name(id);
  return "variable " + (name.empty() ? std::to_string(id) : "'" + name + "'");
}

SolveSummary SolveFromPython(Problem& p, const py::object& options, const py::object& callback,
                             const py::kwargs& overrides,
                             const std::function<SolveSummary(const SolverOptions&)>& solve) {
  SolverOptions o = MakeSolverOptions(options, overrides);
  // verbose prints through Python's print (sys.stdout: notebooks and
  // contextlib.redirect_stdout see it), not from C++ to the process' stderr.
  const bool verbose = o.verbose;
  o.verbose = false;
  if (!callback.is_none() && !PyCallable_Check(callback.ptr())) {
    throw py::type_error("callback must be callable, got " +
                         std::string(py::str(py::type::of(callback).attr("__name__"))));
  }
  for (int id = 0; id < p.num_variables(); ++id) {
    if (!p.IsFixed(id)) ValidatePythonManifold(p, id, VariableWhat(p, id));
  }
  // Python errors raised inside Ceres (measurement functions,
  // manifolds, the callback) land in this solve's slot and are
  // re-raised after Ceres has returned; Ctrl-C only stops the solve.
  ErrorScope scope;
  ErrorSlot& slot = scope.slot();
  // Between iterations the GIL is taken only for Python work: the callback,
  // or Ctrl-C, which Python delivers to the main thread alone. A solve
  // without callback in another thread never takes it, so concurrent solves
  // of C++ measurements run in parallel. The slot is filled on this thread
  // (Ceres calls Python measurements and manifolds back on the thread that
  // started it), so reading it needs no GIL.
  const bool has_callback = !callback.is_none();
  const bool main_thread =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>() ==
      PyThread_get_thread_ident();
  if (verbose) py::print(ProgressHeader(), py::arg("flush") = true);
  o.on_iteration = [&, has_callback, main_thread, verbose](const IterationInfo& info) {
    if (slot.Has()) return false;
    if (!has_callback && !main_thread && !verbose) return true;
    py::gil_scoped_acquire gil;
    if (verbose) py::print(FormatProgress(info), py::arg("flush") = true);
    if (PyErr_CheckSignals() != 0) {
      if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {
        PyErr_Clear();
        return false;
      }
      slot.Store(py::error_already_set());
      return false;
    }
    if (!has_callback) return true;
    try {
      return CallbackContinues(callback(info));
    } catch (py::error_already_set& e) {
      slot.Store(std::move(e));
    } catch (const py::builtin_exception& e) {
      e.set_error();
      slot.Store(py::error_already_set());
    }
    return false;
  };
  // Ctrl-C within an iteration (between its linear solve and its line search):
  // the main thread's signals only, as above.
  if (main_thread) {
    o.should_stop = [&slot]() {
      if (slot.Has()) return true;
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() == 0) return false;
      if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) {
        PyErr_Clear();
      } else {
        slot.Store(py::error_already_set());
      }
      return true;
    };
  }
  SolveSummary s;
  try {
    py::gil_scoped_release release;
    s = solve(o);
  } catch (const std::exception&) {
    if (auto e = slot.Take()) throw std::move(*e);
    throw;
  }
  std::unique_ptr<py::error_already_set> pending = slot.Take();
  if (pending && pending->matches(PyExc_KeyboardInterrupt)) {
    // Ctrl-C inside a Python measurement: keep the estimate.
    s.termination = "interrupted";
    s.usable = true;
    pending.reset();
  }
  if (pending) throw std::move(*pending);
  if (verbose) py::print(FormatSummary(s), py::arg("flush") = true);
  return s;
}

}  // namespace boxplus::python
