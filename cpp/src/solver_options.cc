#include "boxplus/solver_options.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "boxplus/errors.h"

namespace boxplus {

namespace {
std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}
}  // namespace

const std::vector<std::string>& MethodNames() {
  static const std::vector<std::string> names = {"lm", "gn", "gn_ls", "dogleg", "gn_lm"};
  return names;
}

Method ParseMethod(const std::string& name) {
  const std::string n = Lower(name);
  if (n == "lm" || n == "levenberg_marquardt") return Method::kLevenbergMarquardt;
  if (n == "gn" || n == "gauss_newton") return Method::kGaussNewton;
  if (n == "gn_ls" || n == "gauss_newton_line_search") return Method::kGaussNewtonLineSearch;
  if (n == "dogleg") return Method::kDogleg;
  if (n == "gn_lm" || n == "auto") return Method::kGaussNewtonFallback;
  throw Error("unknown method '" + name + "' (expected lm, gn, gn_ls, dogleg or gn_lm/auto)");
}

std::string MethodName(Method method) {
  switch (method) {
    case Method::kLevenbergMarquardt:
      return "lm";
    case Method::kGaussNewton:
      return "gn";
    case Method::kGaussNewtonLineSearch:
      return "gn_ls";
    case Method::kDogleg:
      return "dogleg";
    case Method::kGaussNewtonFallback:
      return "gn_lm";
  }
  return "?";
}

Damping ParseDamping(const std::string& name) {
  const std::string n = Lower(name);
  if (n == "marquardt") return Damping::kMarquardt;
  if (n == "levenberg") return Damping::kLevenberg;
  throw Error("unknown damping '" + name + "' (expected marquardt or levenberg)");
}

std::string DampingName(Damping damping) {
  return damping == Damping::kLevenberg ? "levenberg" : "marquardt";
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
