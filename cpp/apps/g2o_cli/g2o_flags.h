// g2o's command-line spellings for boxplus-g2o: g2o_cli's flags (g2o.cpp)
// rewritten into boxplus-g2o's own before they are parsed, so that one parser
// and one help text describe the tool.
//
//   g2o                        boxplus-g2o
//   -i N                       -i N (same; negative N, g2o's "stop on gain", is refused)
//   -o FILE                    -o FILE (same; '-' is stdout)
//   -solver NAME               --solver M: g2o's NAME = (gn|lm|dl)_(var|fixP_L)[_LINEAR]
//                              → gn, lm, dogleg; the block structure (var, fix6_3…) and
//                              the linear solver (cholmod, csparse, eigen, dense, pcg) do
//                              not apply: boxplus always factorises J'J by sparse Cholesky
//   -robustKernel NAME         --robust: Huber, Cauchy, Tukey, PseudoHuber (= soft_l1,
//                              the same ρ), DCS (dcs), GemanMcClure (geman_mcclure);
//                              g2o's Fair, Saturated, Welsch are refused (no boxplus
//                              kernel)
//   -robustKernelWidth X       --robust-width X (g2o's −1 = the kernel's default 1);
//                              for DCS and GemanMcClure √X, since g2o takes their
//                              width on e'Ωe and boxplus on its square root
//   -guess                     --init spanning-tree (g2o: initial guess by spanning tree)
//   -gaugeId N, -gaugeList L   --gauge L: hold these vertices instead of the first
//   -summary FILE, -stats FILE --summary FILE (appends one line per run), --stats FILE
//                              (the per-iteration lines)
//   -v                         -v (per-iteration lines are on unless -q; kept for g2o)
//   -listSolvers, -listRobustKernels, -listTypes   --list-solvers, ... (print, exit 0)
// Refused with a message naming the flag: -guessOdometry, -inc, -update,
// -marginalize, -computeMarginals, -solverProperties, -printSolverProperties,
// -renameTypes, -solverlib, -typeslib, -gain, -ig, -nonSequential.
#pragma once

#include <cctype>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace boxplus::g2o_cli {

// What a g2o flag that boxplus cannot honour does in g2o, for the refusal.
inline const std::map<std::string, std::string>& RefusedG2oFlags() {
  static const std::map<std::string, std::string> refused = {
      {"-guessOdometry",
       "initial guess by odometry (use -guess, the spanning tree, or "
       "--init chordal)"},
      {"-inc", "incremental optimisation"},
      {"-update", "incremental optimisation"},
      {"-marginalize",
       "Schur complement of the landmarks (boxplus' sparse Cholesky needs "
       "no such switch)"},
      {"-computeMarginals", "marginal covariances (use boxplus' Python API: covariance())"},
      {"-solverProperties",
       "g2o's internal solver properties (use --initial-radius, "
       "--damping, ...)"},
      {"-printSolverProperties", "g2o's internal solver properties"},
      {"-renameTypes", "renaming tags on load"},
      {"-solverlib", "loading a g2o solver library"},
      {"-typeslib", "loading a g2o types library"},
      {"-gain", "stopping on the gain (use --function-tolerance)"},
      {"-ig", "stopping on the gain (use --function-tolerance)"},
      {"-nonSequential", "a robust kernel on loop closures only"},
  };
  return refused;
}

// g2o's solver name → boxplus' method name ("" if it is not one of g2o's).
inline std::string MethodOfG2oSolver(const std::string& name) {
  static const std::regex pattern(
      "(gn|lm|dl)_(var|fix[0-9]+_[0-9]+)(_(cholmod|csparse|eigen|dense|pcg))?");
  std::smatch m;
  if (!std::regex_match(name, m, pattern)) return "";
  return m[1] == "gn" ? "gn" : m[1] == "lm" ? "lm" : "dogleg";
}

// g2o's robust kernel name → boxplus' loss name; "" for g2o's kernels that
// boxplus does not have, the name itself for any other.
inline std::string LossOfG2oKernel(const std::string& name) {
  static const std::map<std::string, std::string> known = {
      {"Huber", "huber"},         {"Cauchy", "cauchy"}, {"Tukey", "tukey"},
      {"PseudoHuber", "soft_l1"}, {"DCS", "dcs"},       {"GemanMcClure", "geman_mcclure"}};
  static const std::vector<std::string> missing = {"Fair", "Saturated", "Welsch", "SaturatedHuber"};
  auto it = known.find(name);
  if (it != known.end()) return it->second;
  for (const auto& m : missing) {
    if (m == name) return "";
  }
  return name;
}

inline const char* kG2oKernelsHelp =
    "g2o's robust kernels: Huber, Cauchy, Tukey, PseudoHuber (= soft_l1), DCS, GemanMcClure; "
    "boxplus' own: huber, cauchy, tukey, soft_l1, arctan, dcs, geman_mcclure";

// Rewrites g2o's spellings in `args` (argv without the program name) into
// boxplus-g2o's; throws std::invalid_argument naming the flag for g2o flags
// that have no boxplus meaning.
inline std::vector<std::string> FromG2oFlags(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  bool width_on_chi2 = false;           // a g2o kernel whose width is on e'Ωe
  size_t width_at = std::string::npos;  // where -robustKernelWidth's value went
  for (size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
      return args[++k];
    };
    const auto refused = RefusedG2oFlags().find(a);
    if (refused != RefusedG2oFlags().end()) {
      throw std::invalid_argument("g2o's " + a + " (" + refused->second +
                                  ") is not supported by boxplus-g2o");
    }
    if (a == "-solver") {
      const std::string name = value();
      const std::string method = MethodOfG2oSolver(name);
      out.insert(out.end(), {"--solver", method.empty() ? name : method});
    } else if (a == "-robustKernel") {
      const std::string name = value();
      const std::string loss = LossOfG2oKernel(name);
      if (loss.empty()) {
        throw std::invalid_argument("-robustKernel " + name + ": g2o's kernel " + name +
                                    " has no boxplus equivalent (" + kG2oKernelsHelp + ")");
      }
      out.insert(out.end(), {"--robust", loss});
      width_on_chi2 = loss == "dcs" || loss == "geman_mcclure";
    } else if (a == "-robustKernelWidth") {
      const std::string w = value();
      // g2o's default −1 means "the kernel's own width", 1 for every kernel.
      out.insert(out.end(), {"--robust-width", w == "-1" || w == "-1.0" ? "1" : w});
      width_at = out.size() - 1;
    } else if (a == "-guess") {
      out.insert(out.end(), {"--init", "spanning-tree"});
    } else if (a == "-gaugeId" || a == "-gaugeList") {
      out.insert(out.end(), {"--gauge", value()});
    } else if (a == "-summary") {
      out.insert(out.end(), {"--summary", value()});
    } else if (a == "-stats") {
      out.insert(out.end(), {"--stats", value()});
    } else if (a == "-listSolvers") {
      out.push_back("--list-solvers");
    } else if (a == "-listRobustKernels") {
      out.push_back("--list-robust-kernels");
    } else if (a == "-listTypes") {
      out.push_back("--list-types");
    } else {
      out.push_back(a);
    }
  }
  if (width_on_chi2 && width_at != std::string::npos) {
    double w = 0.0;
    try {
      w = std::stod(out[width_at]);
    } catch (const std::exception&) {
      throw std::invalid_argument("-robustKernelWidth " + out[width_at] + ": not a number");
    }
    if (!(w > 0.0) || !std::isfinite(w)) {
      throw std::invalid_argument("-robustKernelWidth " + out[width_at] +
                                  ": must be positive and finite");
    }
    std::ostringstream s;
    s.precision(17);
    s << std::sqrt(w);
    out[width_at] = s.str();
  }
  return out;
}

}  // namespace boxplus::g2o_cli
