// Bindings of the solver vocabulary (boxplus/solver_options.h, progress.h):
// SolverOptions, IterationInfo and SolveSummary as classes with keyword
// construction, attributes, repr, todict(), == and pickling (pycolmap's
// MakeDataclass is the model), and the one progress format.
#include "solver.h"

#include <pybind11/stl.h>
#include <algorithm>

#include <functional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "bindings.h"
#include "boxplus/progress.h"
#include "errors.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {

// One attribute of a bound record: its name, how to read it as a Python
// object and how to set it from one (raising TypeError naming it).
template <class T>
struct Field {
  std::string name;
  std::function<py::object(const T&)> get;
  std::function<void(T&, py::handle)> set;
};

std::string TypeName(py::handle v) { return py::str(py::type::of(v).attr("__name__")); }

template <class M>
M CastField(py::handle v, const std::string& owner, const std::string& name) {
  // bool is an int in Python: refuse it for numbers, and numbers for bools.
  const bool is_bool =
      py::isinstance<py::bool_>(v) || TypeName(v) == "bool_" || TypeName(v) == "bool";
  bool ok = true;
  if constexpr (std::is_same_v<M, bool>) {
    ok = is_bool;
  } else if constexpr (std::is_arithmetic_v<M>) {
    ok = !is_bool;
  }
  if (ok) {
    try {
      return v.cast<M>();
    } catch (const py::cast_error&) {
    }
  }
  const char* expected = std::is_same_v<M, bool>     ? "a bool"
                         : std::is_same_v<M, int>    ? "an int (32-bit)"
                         : std::is_same_v<M, double> ? "a float"
                                                     : "a str";
  throw py::type_error(owner + "." + name + " must be " + expected + ", got " + TypeName(v) + " " +
                       std::string(py::repr(v)).substr(0, 80));
}

template <class T, class M>
Field<T> Member(const std::string& owner, const char* name, M T::*pm) {
  return {name, [pm](const T& t) { return py::cast(t.*pm); },
          [pm, owner, n = std::string(name)](T& t, py::handle v) {
            t.*pm = CastField<M>(v, owner, n);
          }};
}

// χ² = 2 × a Ceres cost, read and written through the cost member.
template <class T>
Field<T> Chi2(const std::string& owner, const char* name, double T::*cost) {
  return {name, [cost](const T& t) { return py::cast(2 * (t.*cost)); },
          [cost, owner, n = std::string(name)](T& t, py::handle v) {
            t.*cost = CastField<double>(v, owner, n) / 2;
          }};
}

template <class T>
const Field<T>& Find(const std::vector<Field<T>>& fields, const std::string& owner,
                     const std::string& name) {
  for (const auto& f : fields) {
    if (f.name == name) return f;
  }
  std::string names;
  for (const auto& f : fields) names += (names.empty() ? "" : ", ") + f.name;
  throw py::type_error(owner + " has no field '" + name + "' (fields: " + names + ")");
}

template <class T>
void Apply(T& t, const std::vector<Field<T>>& fields, const std::string& owner,
           const py::dict& values) {
  for (auto item : values) {
    Find(fields, owner, py::str(item.first)).set(t, item.second);
  }
}

template <class T>
py::dict ToDict(const T& t, const std::vector<Field<T>>& fields) {
  py::dict d;
  for (const auto& f : fields) d[py::str(f.name)] = f.get(t);
  return d;
}

// Keyword construction, read-only or read-write attributes, repr,
// todict(), == and pickling from the field table. The repr shows the fields
// named in `repr_fields` (all when empty): a record with long text fields
// (a solve's full Ceres report) stays one line; todict() has them all.
// `given(t, name)`, when set, records each field set by keyword or assignment
// (SolverOptions::given: an owner's defaults fill the others).
template <class T>
void BindRecord(py::class_<T>& cls, const std::string& owner, std::vector<Field<T>> fields,
                bool writable, std::function<void(const T&)> validate,
                std::vector<std::string> repr_fields = {},
                std::function<void(T&, const std::string&)> given = nullptr) {
  auto table = std::make_shared<std::vector<Field<T>>>(std::move(fields));
  cls.def(py::init([table, owner, validate, given](const py::kwargs& kw) {
            T t;
            Apply(t, *table, owner, kw);
            if (given) {
              given(t, "");
              for (auto item : kw) given(t, std::string(py::str(item.first)));
            }
            if (validate) validate(t);
            return t;
          }),
          ("Keyword construction; unnamed fields keep their defaults. Fields: " +
           [&] {
             std::string s;
             for (const auto& f : *table) s += (s.empty() ? "" : ", ") + f.name;
             return s;
           }())
              .c_str());
  for (const auto& f : *table) {
    if (writable) {
      cls.def_property(f.name.c_str(), f.get, [f, validate, given](T& t, py::handle v) {
        T candidate = t;
        f.set(candidate, v);
        if (validate) validate(candidate);
        if (given) given(candidate, f.name);
        t = candidate;
      });
    } else {
      cls.def_property_readonly(f.name.c_str(), f.get);
    }
  }
  cls.def(
      "todict", [table](const T& t) { return ToDict(t, *table); },
      "The fields as a dict (keyword arguments of the constructor).");
  cls.def("__repr__", [table, owner, repr_fields](const T& t) {
    std::string s = owner + "(";
    bool first = true;
    for (const auto& f : *table) {
      if (!repr_fields.empty() &&
          std::find(repr_fields.begin(), repr_fields.end(), f.name) == repr_fields.end()) {
        continue;
      }
      s += (first ? "" : ", ") + f.name + "=" + std::string(py::repr(f.get(t)));
      first = false;
    }
    return s + ")";
  });
  cls.def("__eq__", [table](const T& a, py::object b) {
    if (!py::isinstance<T>(b)) return false;
    return ToDict(a, *table).equal(ToDict(b.cast<const T&>(), *table));
  });
  cls.def("__ne__", [table](const T& a, py::object b) {
    if (!py::isinstance<T>(b)) return true;
    return !ToDict(a, *table).equal(ToDict(b.cast<const T&>(), *table));
  });
  cls.attr("__hash__") = py::none();
  cls.def("__copy__", [](const T& t) { return T(t); });
  cls.def(
      "__deepcopy__", [](const T& t, py::dict) { return T(t); }, py::arg("memo"));
  // The state: the fields, and (for SolverOptions) which of them were given.
  cls.def(py::pickle(
      [table](const T& t) {
        py::dict d = ToDict(t, *table);
        if constexpr (std::is_same_v<T, SolverOptions>) {
          if (t.given) d["__given__"] = std::vector<std::string>(t.given->begin(), t.given->end());
        }
        return d;
      },
      [table, owner, given](py::dict d) {
        T t;
        py::object names = d.attr("pop")("__given__", py::none());
        Apply(t, *table, owner, d);
        if (given && !names.is_none()) {
          given(t, "");
          for (auto n : names) given(t, std::string(py::str(n)));
        }
        return t;
      }));
}

std::vector<Field<SolverOptions>> OptionFields() {
  using O = SolverOptions;
  const std::string n = "SolverOptions";
  return {
      {"method", [](const O& o) { return py::cast(MethodName(o.method)); },
       [n](O& o, py::handle v) { o.method = ParseMethod(CastField<std::string>(v, n, "method")); }},
      Member(n, "max_iterations", &O::max_iterations),
      Member(n, "function_tolerance", &O::function_tolerance),
      Member(n, "gradient_tolerance", &O::gradient_tolerance),
      Member(n, "parameter_tolerance", &O::parameter_tolerance),
      Member(n, "num_threads", &O::num_threads),
      Member(n, "initial_trust_region_radius", &O::initial_trust_region_radius),
      {"damping", [](const O& o) { return py::cast(DampingName(o.damping)); },
       [n](O& o, py::handle v) {
         o.damping = ParseDamping(CastField<std::string>(v, n, "damping"));
       }},
      Member(n, "jacobi_scaling", &O::jacobi_scaling),
      Member(n, "use_nonmonotonic_steps", &O::use_nonmonotonic_steps),
      Member(n, "max_consecutive_nonmonotonic_steps", &O::max_consecutive_nonmonotonic_steps),
      Member(n, "verbose", &O::verbose),
  };
}

std::vector<Field<IterationInfo>> InfoFields() {
  using I = IterationInfo;
  const std::string n = "IterationInfo";
  return {
      Member(n, "iteration", &I::iteration),
      Member(n, "cost", &I::cost),
      Chi2(n, "chi2", &I::cost),
      Member(n, "cost_change", &I::cost_change),
      Member(n, "gradient_max_norm", &I::gradient_max_norm),
      Member(n, "step_norm", &I::step_norm),
      Member(n, "trust_region_radius", &I::trust_region_radius),
      Member(n, "step_length", &I::step_length),
      Member(n, "iteration_time_s", &I::iteration_time_s),
      Member(n, "cumulative_time_s", &I::cumulative_time_s),
      Member(n, "step_is_successful", &I::step_is_successful),
  };
}

std::vector<Field<SolveSummary>> SummaryFields() {
  using S = SolveSummary;
  const std::string n = "SolveSummary";
  return {
      Member(n, "initial_cost", &S::initial_cost),
      Member(n, "final_cost", &S::final_cost),
      Chi2(n, "initial_chi2", &S::initial_cost),
      Chi2(n, "final_chi2", &S::final_cost),
      Member(n, "iterations", &S::iterations),
      Member(n, "time_s", &S::time_s),
      Member(n, "termination", &S::termination),
      Member(n, "message", &S::message),
      Member(n, "usable", &S::usable),
      Member(n, "report", &S::report),
  };
}

}  // namespace

SolverOptions MakeSolverOptions(const py::object& options, const py::dict& overrides) {
  SolverOptions o;
  o.given.emplace();  // from Python the fields set are always known (none: every default)
  if (!options.is_none()) {
    if (!py::isinstance<SolverOptions>(options)) {
      throw py::type_error("options must be a boxplus.SolverOptions, got " + TypeName(options));
    }
    o = options.cast<SolverOptions>();
    if (!o.given) o.given.emplace();
  }
  py::dict rest;
  for (auto item : overrides) {
    // nonmonotonic_steps=n: the short form of the two nonmonotonic fields.
    if (std::string(py::str(item.first)) == "nonmonotonic_steps") {
      const int n = CastField<int>(item.second, "SolverOptions", "nonmonotonic_steps");
      if (n < 0) throw py::value_error("nonmonotonic_steps must be >= 0, got " + std::to_string(n));
      o.use_nonmonotonic_steps = n > 0;
      if (n > 0) o.max_consecutive_nonmonotonic_steps = n;
    } else {
      rest[item.first] = item.second;
    }
  }
  static const auto fields = OptionFields();
  Apply(o, fields, "SolverOptions", rest);
  for (auto item : rest) o.given->insert(std::string(py::str(item.first)));
  for (auto item : overrides) {
    if (std::string(py::str(item.first)) == "nonmonotonic_steps") {
      o.given->insert({"use_nonmonotonic_steps", "max_consecutive_nonmonotonic_steps"});
    }
  }
  Validate(o);
  return o;
}

void RegisterSolver(py::module_& m) {
  py::class_<SolverOptions> options(m, "SolverOptions", R"doc(
Settings of a solve (boxplus/solver_options.h), shared by every problem.

Construct with keywords, e.g. ``SolverOptions(method="gn_ls", max_iterations=50)``.

Attributes
----------
method : {'lm', 'gn', 'gn_ls', 'dogleg'}
    Levenberg–Marquardt, Gauss–Newton (trust region, undamped), Gauss–Newton
    with a backtracking line search along x ⊞ αδ (boxplus' own; the
    trust-region fields do not apply), or Powell's dogleg.
max_iterations, function_tolerance, gradient_tolerance, parameter_tolerance, num_threads
    Ceres' stopping rules and threads.
initial_trust_region_radius : float
    μ₀ (LM solves (JᵀJ + D/μ) δ = −Jᵀr); 1e16 starts like Gauss–Newton.
damping : {'marquardt', 'levenberg'}
    D = diag(JᵀJ) (Ceres' default) or D = I (λI, as g2o's LM).
jacobi_scaling : bool
    Scale the columns of J by 1/(1 + ‖J_k‖) before solving.
use_nonmonotonic_steps, max_consecutive_nonmonotonic_steps
    Accept up to that many consecutive cost increases while the best cost
    still decreases.
verbose : bool
    C++ prints one line per iteration (progress_header/format_progress) to stderr.
)doc");
  BindRecord<SolverOptions>(
      options, "SolverOptions", OptionFields(), true, [](const SolverOptions& o) { Validate(o); },
      {},
      [](SolverOptions& o, const std::string& name) {
        if (!o.given) o.given.emplace();
        if (name == "nonmonotonic_steps") {
          o.given->insert({"use_nonmonotonic_steps", "max_consecutive_nonmonotonic_steps"});
        } else if (!name.empty()) {
          o.given->insert(name);
        }
      });
  options.def_property_readonly(
      "given",
      [](const SolverOptions& o) {
        return o.given ? std::vector<std::string>(o.given->begin(), o.given->end())
                       : std::vector<std::string>();
      },
      "The fields set by keyword or assignment: a pose graph's solve takes these and its own "
      "defaults for the others (boxplus.slam.SOLVER_DEFAULTS).");
  m.def("solver_option_names", &SolverOptionNames, "The settable fields of SolverOptions.");

  py::class_<IterationInfo> info(m, "IterationInfo", R"doc(
What the per-iteration callback receives (read-only).

``cost`` is Ceres' ½ Σ ρ(‖rᵢ‖²); ``chi2`` = 2·cost is what the progress lines
print. ``trust_region_radius`` is 0 for the line search, whose step length α
is ``step_length`` (1 for trust-region methods).
)doc");
  BindRecord<IterationInfo>(info, "IterationInfo", InfoFields(), false, nullptr);

  py::class_<SolveSummary> summary(m, "SolveSummary", R"doc(
What a solve did and why it stopped (read-only).

``termination`` is 'convergence', 'no_convergence', 'interrupted' (callback or
Ctrl-C: the estimate is the last accepted one) or 'failure'; ``usable`` says
whether the estimate may be used. ``initial_chi2``/``final_chi2`` = 2 × cost.
)doc");
  BindRecord<SolveSummary>(
      summary, "SolveSummary", SummaryFields(), false, nullptr,
      {"termination", "usable", "iterations", "initial_chi2", "final_chi2", "time_s"});
  summary.def("__str__", [](const SolveSummary& s) { return SafeStr(FormatSummary(s)); });

  m.def("progress_header", &ProgressHeader, "The column titles of format_progress lines.");
  m.def("format_progress", &FormatProgress, py::arg("info"),
        "One progress line (χ², change, |gradient|, |step|, radius/α, time) for an iteration.");
  m.def(
      "format_summary", [](const SolveSummary& s) { return SafeStr(FormatSummary(s)); },
      py::arg("summary"), "The closing line of a solve: termination, χ² before → after, time.");
}

}  // namespace boxplus::python
