#include "boxplus/solver_options.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boxplus/errors.h"
#include "boxplus/named_enum.h"

namespace boxplus {

namespace {

const NamedEnum<Method>& Methods() {
  static const NamedEnum<Method> names(
      "method", {{Method::kLevenbergMarquardt, "lm", {"levenberg_marquardt"}},
                 {Method::kGaussNewton, "gn", {"gauss_newton"}},
                 {Method::kGaussNewtonLineSearch, "gn_ls", {"gauss_newton_line_search"}},
                 {Method::kDogleg, "dogleg", {}},
                 {Method::kGaussNewtonFallback, "gn_lm", {"auto"}}});
  return names;
}

const NamedEnum<Damping>& Dampings() {
  static const NamedEnum<Damping> names(
      "damping", {{Damping::kMarquardt, "marquardt", {}}, {Damping::kLevenberg, "levenberg", {}}});
  return names;
}

}  // namespace

const std::vector<std::string>& MethodNames() {
  static const std::vector<std::string> names = Methods().Names();
  return names;
}

Method ParseMethod(const std::string& name) { return Methods().Parse(name); }

std::string MethodName(Method method) { return Methods().Name(method); }

Damping ParseDamping(const std::string& name) { return Dampings().Parse(name); }

std::string DampingName(Damping damping) { return Dampings().Name(damping); }

namespace {

// Each settable field: its name and how to copy it from one options to another.
struct FieldCopy {
  const char* name;
  void (*copy)(const SolverOptions& from, SolverOptions* to);
};

#define BOXPLUS_FIELD(f)                                             \
  FieldCopy {                                                        \
#f, [](const SolverOptions& a, SolverOptions* b) { b->f = a.f; } \
  }

const std::vector<FieldCopy>& Fields() {
  static const std::vector<FieldCopy> fields = {
      BOXPLUS_FIELD(method),
      BOXPLUS_FIELD(max_iterations),
      BOXPLUS_FIELD(function_tolerance),
      BOXPLUS_FIELD(gradient_tolerance),
      BOXPLUS_FIELD(parameter_tolerance),
      BOXPLUS_FIELD(num_threads),
      BOXPLUS_FIELD(initial_trust_region_radius),
      BOXPLUS_FIELD(damping),
      BOXPLUS_FIELD(jacobi_scaling),
      BOXPLUS_FIELD(use_nonmonotonic_steps),
      BOXPLUS_FIELD(max_consecutive_nonmonotonic_steps),
      BOXPLUS_FIELD(verbose),
  };
  return fields;
}
#undef BOXPLUS_FIELD

}  // namespace

const std::vector<std::string>& SolverOptionNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const FieldCopy& f : Fields()) n.emplace_back(f.name);
    return n;
  }();
  return names;
}

SolverOptions WithDefaults(const SolverOptions& defaults, const SolverOptions& options) {
  if (!options.given) return options;
  SolverOptions out = defaults;
  for (const std::string& name : *options.given) {
    const auto it = std::find_if(Fields().begin(), Fields().end(),
                                 [&](const FieldCopy& f) { return name == f.name; });
    BOXPLUS_CHECK(it != Fields().end(), "SolverOptions has no field '", name, "'");
    it->copy(options, &out);
  }
  out.on_iteration = options.on_iteration;
  out.should_stop = options.should_stop;
  out.given = options.given;
  return out;
}

void Validate(const SolverOptions& o) {
  BOXPLUS_CHECK(o.max_iterations >= 0, "max_iterations must be >= 0, got ", o.max_iterations);
  BOXPLUS_CHECK(o.num_threads >= 1, "num_threads must be >= 1, got ", o.num_threads);
  BOXPLUS_CHECK(std::isfinite(o.function_tolerance) && o.function_tolerance >= 0,
                "function_tolerance must be finite and >= 0, got ", o.function_tolerance);
  BOXPLUS_CHECK(std::isfinite(o.gradient_tolerance) && o.gradient_tolerance >= 0,
                "gradient_tolerance must be finite and >= 0, got ", o.gradient_tolerance);
  BOXPLUS_CHECK(std::isfinite(o.parameter_tolerance) && o.parameter_tolerance >= 0,
                "parameter_tolerance must be finite and >= 0, got ", o.parameter_tolerance);
  BOXPLUS_CHECK(o.initial_trust_region_radius > 0 && std::isfinite(o.initial_trust_region_radius),
                "initial_trust_region_radius must be > 0 and finite, got ",
                o.initial_trust_region_radius);
  BOXPLUS_CHECK(o.max_consecutive_nonmonotonic_steps >= 0,
                "max_consecutive_nonmonotonic_steps must be >= 0, got ",
                o.max_consecutive_nonmonotonic_steps);
}

}  // namespace boxplus
