// boxplus-g2o's command line: every option, its help and its checks in one
// place, parsed by CLI11 (so `--iterations=5`, `-qi5` and `--` work as in any
// GNU-style tool). g2o's own spellings (-solver, -robustKernel, ...) are
// rewritten into these before parsing (g2o_flags.h), so one parser and one
// help text describe the tool. Names are turned into enums by the library's
// own parsers (ParseMethod, ParsePoseErrorConvention, ParseInitMethod, ...),
// never by a table here.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "boxplus/certify/certify.h"
#include "boxplus/errors.h"
#include "boxplus/io/atomic_file.h"
#include "boxplus/io/g2o.h"
#include "boxplus/loss.h"
#include "boxplus/slam/load.h"
#include "boxplus/solver_options.h"
#include "boxplus/version.h"
#include "g2o_flags.h"

namespace boxplus::g2o_cli {

// What the command line asks for, with boxplus' defaults where it is silent.
struct CommandLine {
  std::string input;  // '-': standard input
  std::string output, summary_file, stats_file, outliers_file;
  std::string solver = "auto", convention = "g2o", init = "best", outlier_mode = "auto";
  std::vector<int> gauge;
  int threads = 1;
  bool threads_given = false, convention_given = false;
  bool quiet = false, full_report = false, certify = false, overwrite_input = false;
  slam::OutlierOptions outlier_options;
  certify::CertifyOptions certify_options;
  slam::LoadOptions load;
  SolverOptions solver_options = slam::DefaultSolverOptions();
};

inline constexpr const char* kUsage =
    "usage: boxplus-g2o [options] input.g2o     ('-' reads standard input)\n\n";

inline constexpr const char* kDescription =
    R"(Optimises a pose graph in g2o format (the slam2d/slam3d tags of g2o),
TORO format (VERTEX2, EDGE2, VERTEX3, EDGE3 with or without information,
EQUIV) or with GTSAM's LANDMARK2 landmark lines; --list-types lists every tag
read, with its fields. The gauge is fixed by the FIX lines, else by the first
pose vertex (not at all when a pose prior fixes it).)";

inline constexpr const char* kFooter =
    R"(g2o's spellings are accepted too: -solver NAME (gn_var, lm_fix6_3_cholmod,
dl_var, ...: gn, lm or dogleg), -robustKernel NAME (Huber, Cauchy, Tukey,
PseudoHuber, DCS, GemanMcClure), -robustKernelWidth X, -guess (spanning-tree
initialisation), -gaugeId N, -gaugeList L, -summary FILE, -stats FILE, -v,
-listSolvers, -listRobustKernels, -listTypes; g2o's flags without a boxplus
meaning (-inc, -marginalize, -solverProperties, ...) are refused by name.

Output: on stdout one line per iteration in boxplus' progress format (chi2 =
sum of e'Ωe, with the robust kernel if any; twice Ceres' cost; cumulative time
in seconds); on stderr the '#' diagnostics (file, sizes, times, initial and
final chi2, memory), the summary and, while a big file loads, about once a
second a line with the lines read and the bytes of the file. Ctrl-C stops the
solver after the current iteration, writes the last accepted estimate to -o
and exits with 130.

Exit codes: 0 success, 1 the solver failed, 2 bad input, usage or a failed
write (every output is written atomically: a failed write keeps the previous
file), 130 interrupted.)";

// CLI11's help with the usage line first, then what the tool does.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_usage(const CLI::App* app, std::string) const override {
    return std::string(kUsage) + app->get_description() + "\n";
  }
  std::string make_description(const CLI::App*) const override { return ""; }
};

// A count (iterations, ranks): an integer in [0, 10⁹], named in the error.
inline const CLI::Validator kCount(
    [](std::string& v) {
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || n < 0 || n > 1000000000) {
        return "not a non-negative integer: '" + v + "'";
      }
      return std::string();
    },
    "");

[[noreturn]] inline void UsageError(const std::string& what) {
  std::fprintf(stderr, "boxplus-g2o: %s\n(try boxplus-g2o --help)\n", what.c_str());
  std::exit(2);
}

inline std::vector<int> ParseIdList(const std::string& opt, const std::string& s) {
  std::vector<int> ids;
  size_t start = 0;
  while (start <= s.size()) {
    const size_t comma = s.find(',', start);
    const std::string item = s.substr(start, comma == std::string::npos ? comma : comma - start);
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v < -2000000000L || v > 2000000000L) {
      UsageError(opt + ": not a list of vertex ids: '" + s + "'");
    }
    ids.push_back(static_cast<int>(v));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return ids;
}

inline void ListSolvers() {
  std::printf("boxplus methods:");
  for (const auto& m : MethodNames()) std::printf(" %s", m.c_str());
  std::printf(
      " auto\ng2o's names: (gn|lm|dl)_(var|fixP_L)[_cholmod|_csparse|_eigen|_dense|_pcg],"
      " e.g. gn_var, lm_fix6_3_cholmod, dl_var → gn, lm, dogleg (sparse Cholesky)\n");
}

inline void ListRobustKernels() {
  std::printf("boxplus:");
  for (const auto& l : LossNames()) std::printf(" %s", l.c_str());
  std::printf("\n%s\n", kG2oKernelsHelp);
}

// The reader's tag table (io::RecordTags), a line per tag: format, tag, fields.
inline void ListTypes() {
  for (const io::TagInfo& t : io::RecordTags()) {
    std::printf("%-22s %-24s %s\n", io::ToString(t.family), t.tag.c_str(), t.fields.c_str());
  }
}

// Parses argv into *cl. Returns an exit code when the run ends here (--help,
// --version, a --list-* without input: 0); a usage error exits with 2 naming
// the option.
inline std::optional<int> ParseCommandLine(int argc, char** argv, CommandLine* cl) {
  std::vector<std::string> args;
  try {
    args = FromG2oFlags(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::invalid_argument& e) {
    UsageError(e.what());
  }
  SolverOptions& so = cl->solver_options;
  int iterations = so.max_iterations;  // the defaults are DefaultSolverOptions()'s
  int nonmonotonic = so.use_nonmonotonic_steps ? so.max_consecutive_nonmonotonic_steps : 0;
  std::string gauge;
  bool verbose = false, list_solvers = false, list_kernels = false, list_types = false;
  std::string damping;  // parsed only when given (DefaultSolverOptions() sets it otherwise)
  bool jacobi_scaling = false, no_jacobi_scaling = false;

  CLI::App app(kDescription, "boxplus-g2o");
  app.footer(kFooter);
  app.formatter(std::make_shared<HelpFormatter>());
  app.get_formatter()->column_width(25);
  // As g2o and most tools: a repeated option's last value holds.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.set_version_flag("--version", std::string("boxplus-g2o ") + BOXPLUS_VERSION_STRING,
                       "print the version");
  app.set_help_flag("-h,--help", "this help");

  app.add_option("input", cl->input, "the graph file ('-': standard input)")->type_name("FILE");
  app.allow_extras();  // left over: a second file or an unknown option, named below
  app.add_option("-i,--iterations", iterations, "maximum number of iterations (default 100)")
      ->type_name("N")
      ->check(kCount);
  app.add_option("-s,--solver", cl->solver,
                 "gn-lm (default; alias auto): Gauss-Newton with a\n"
                 "backtracking line search while its full steps hold,\n"
                 "then Levenberg-Marquardt (chosen and measured on a\n"
                 "generated suite of graphs, README \"Graph SLAM\"); lm\n"
                 "(Levenberg-Marquardt), gn (Gauss-Newton: undamped, the\n"
                 "trust region only rejects steps), gn-ls (Gauss-Newton\n"
                 "with a backtracking line search), dogleg")
      ->type_name("NAME");
  app.add_option("-r,--robust", cl->load.graph.robust,
                 "robust kernel: none (default), huber, cauchy, tukey,\n"
                 "arctan, softl1, dcs (dynamic covariance scaling),\n"
                 "geman_mcclure")
      ->type_name("NAME");
  app.add_option("-w,--robust-width", cl->load.graph.robust_width,
                 "kernel width on sqrt(e'Ωe) (default 1)")
      ->type_name("W");
  app.add_option("--outlier-mode", cl->outlier_mode,
                 "wrong loop closures: auto (default: when the least-\n"
                 "squares solution is implausible, chi2/dof > 10 or a\n"
                 "loop closure far beyond its chi2 bound, judge\n"
                 "the loop closures by graduated non-convexity with\n"
                 "truncated least squares and return the inliers'\n"
                 "optimum), gnc-tls or gnc-gm (always), off (never: the\n"
                 "lowest least-squares minimum, from several starts)")
      ->type_name("NAME");
  app.add_option("--inlier-probability", cl->outlier_options.inlier_probability,
                 "an inlier's e'Ωe is below the P-quantile of chi2(d)\n"
                 "(d = 3 in 2D, 6 in 3D; default 0.99)")
      ->type_name("P");
  app.add_option("--outliers", cl->outliers_file,
                 "write the edges judged wrong (file line, ids, e'Ωe)")
      ->type_name("FILE");
  app.add_option("-t,--threads", cl->threads,
                 "threads for the Jacobians and the factorisation's BLAS\n"
                 "(default: the Jacobians on one, the BLAS on every core;\n"
                 "OPENBLAS_NUM_THREADS, when set, decides the BLAS threads)")
      ->type_name("N");
  app.add_option("-o,--output", cl->output,
                 "write the optimised graph (ids and order kept); '-' is\n"
                 "stdout (then every other line goes to stderr); written\n"
                 "whole or not at all, never over the input unless\n"
                 "--overwrite-input is given")
      ->type_name("FILE");
  app.add_flag("--overwrite-input", cl->overwrite_input, "let -o replace the input file");
  app.add_option("-c,--convention", cl->convention,
                 "pose error: g2o (default; [t, vec(q)] of z⁻¹xᵢ⁻¹xⱼ, as\n"
                 "g2o's EdgeSE2/3), log (GTSAM's Pose2/Pose3 Logmap) or\n"
                 "sesync (alias chordal: SE-Sync's objective\n"
                 "Σ κ‖Rj − Ri R̃ij‖²_F + τ‖tj − ti − Ri t̃ij‖²)")
      ->type_name("NAME");
  app.add_option("--init", cl->init,
                 "best (default: the file's estimate or the chordal\n"
                 "relaxation, whichever has the lower chi2), file,\n"
                 "spanning-tree, chordal")
      ->type_name("NAME");
  app.add_flag("--skip-unknown", cl->load.read.skip_unknown_tags,
               "skip lines with unknown tags (counted in a warning)");
  app.add_flag("--repair-information", cl->load.read.repair_information,
               "replace information matrices that are not positive\n"
               "definite by the nearest positive-definite one (counted\n"
               "in a warning)");
  app.add_option("--initial-radius", so.initial_trust_region_radius,
                 "initial trust-region radius of lm and dogleg (default\n"
                 "1e16: lm starts as Gauss-Newton and damps only after a\n"
                 "step fails; Ceres' own default is 1e4)")
      ->type_name("X");
  app.add_option("--damping", damping,
                 "lm's damping: levenberg (lambda*I, as g2o's LM; default)\n"
                 "or marquardt (diag(J'J), Ceres' default)")
      ->type_name("NAME");
  app.add_flag("--jacobi-scaling", jacobi_scaling,
               "scale the columns of J by 1/(1+|J_k|) (Ceres' default;\n"
               "off by default here)");
  app.add_flag("--no-jacobi-scaling", no_jacobi_scaling)->group("");  // the default, spelt out
  app.add_option("--nonmonotonic", nonmonotonic,
                 "accept up to N consecutive cost increases while the\n"
                 "best cost still decreases (default 5; 0: monotonic)")
      ->type_name("N")
      ->check(kCount);
  app.add_option("--function-tolerance", so.function_tolerance,
                 "Ceres' stopping tolerances (defaults 1e-10,")
      ->type_name("X");
  app.add_option("--gradient-tolerance", so.gradient_tolerance, "1e-12,")->type_name("X");
  app.add_option("--parameter-tolerance", so.parameter_tolerance, "1e-10)")->type_name("X");
  app.add_option("--gauge", gauge,
                 "hold these vertices fixed (instead of the\n"
                 "FIX lines or the first vertex)")
      ->type_name("ID[,ID...]");
  app.add_flag("--certify", cl->certify,
               "after solving, prove the solution globally optimal or\n"
               "not (SE-Sync's certificate: one sparse Cholesky\n"
               "factorisation) and, if it is not, escape the saddle by\n"
               "the Riemannian staircase and solve again (README\n"
               "\"Certified pose graphs\"); implies -c sesync unless -c\n"
               "is given, in which case the certificate is only\n"
               "evaluated at that convention's solution");
  app.add_option("--certify-tolerance", cl->certify_options.certificate.relative_tolerance,
                 "certify when f - f* <= X f is proven (default 1e-6)")
      ->type_name("X");
  app.add_option("--max-rank", cl->certify_options.max_rank,
                 "highest rank of the staircase (default 10; 2 or 3, the\n"
                 "graph's dimension, verifies only)")
      ->type_name("N")
      ->check(kCount);
  app.add_option("--summary", cl->summary_file,
                 "append one line about the run (file, sizes, chi2,\n"
                 "iterations, time, status) to FILE")
      ->type_name("FILE");
  app.add_option("--stats", cl->stats_file, "write the per-iteration lines to FILE")
      ->type_name("FILE");
  app.add_flag("-q,--quiet", cl->quiet, "no per-iteration lines, no progress while loading");
  app.add_flag("-v,--verbose", verbose, "per-iteration lines (the default; for g2o's -v)");
  app.add_flag("--report", cl->full_report,
               "print the solver's full report at the end (Ceres', or\n"
               "gn-ls' own, naming its Cholesky and ordering)");
  app.add_flag("--list-solvers", list_solvers, "print the solver names accepted and exit");
  app.add_flag("--list-robust-kernels", list_kernels, "print the kernel names and exit");
  app.add_flag("--list-types", list_types, "print the tags read, with their fields, and exit");

  try {
    std::reverse(args.begin(), args.end());  // CLI11 takes the arguments last first
    app.parse(args);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::CallForVersion& e) {
    std::printf("%s\n", e.what());
    return 0;
  } catch (const CLI::ParseError& e) {
    UsageError(e.what());
  }

  if (list_solvers) ListSolvers();
  if (list_kernels) ListRobustKernels();
  if (list_types) ListTypes();
  bool after_dashes = false;  // "--": what follows is a file, even if it starts with '-'
  for (const std::string& extra : app.remaining()) {
    if (extra == "--" && !after_dashes) {
      after_dashes = true;
    } else if (!after_dashes && extra.size() > 1 && extra[0] == '-') {
      UsageError("unknown option " + extra);
    } else if (cl->input.empty()) {
      cl->input = extra;
    } else {
      UsageError("more than one input file ('" + cl->input + "', '" + extra + "')");
    }
  }
  if ((list_solvers || list_kernels || list_types) && cl->input.empty()) return 0;
  if (cl->input.empty()) UsageError("no input file");
  if (cl->threads < 1) UsageError("--threads must be >= 1");
  // A user's input is never written over without being asked: -o, --summary,
  // --outliers and --stats naming the input file (through any path, link or
  // symlink) are refused.
  for (const auto& [flag, path] : {std::pair<std::string, std::string>{"-o", cl->output},
                                   {"--summary", cl->summary_file},
                                   {"--outliers", cl->outliers_file},
                                   {"--stats", cl->stats_file}}) {
    if (!path.empty() && path != "-" && cl->input != "-" && io::SameFile(path, cl->input) &&
        !(cl->overwrite_input && flag == "-o")) {
      UsageError(flag + " '" + path + "' is the input file '" + cl->input + "'; write elsewhere" +
                 (flag == "-o" ? ", or give --overwrite-input to replace it" : ""));
    }
  }
  cl->threads_given = app.count("--threads") > 0;
  cl->convention_given = app.count("--convention") > 0;
  if (verbose && app.count("--quiet") == 0) cl->quiet = false;
  const double p = cl->outlier_options.inlier_probability;
  if (!(p > 0 && p < 1)) UsageError("--inlier-probability must be in (0, 1)");
  if (!(cl->certify_options.certificate.relative_tolerance > 0)) {
    UsageError("--certify-tolerance must be > 0");
  }
  if (!(so.initial_trust_region_radius > 0)) UsageError("--initial-radius must be > 0");
  if (!gauge.empty()) cl->gauge = ParseIdList("--gauge", gauge);
  so.max_iterations = iterations;
  if (jacobi_scaling || no_jacobi_scaling) so.jacobi_scaling = jacobi_scaling && !no_jacobi_scaling;
  so.use_nonmonotonic_steps = nonmonotonic > 0;
  so.max_consecutive_nonmonotonic_steps = nonmonotonic;
  so.num_threads = cl->threads;
  // The vocabulary's one parser each (solver_options.h, loss.h, the pose
  // error convention, the initialisation, the outlier mode).
  try {
    so.method = ParseMethod(cl->solver);
    if (app.count("--damping")) so.damping = ParseDamping(damping);
    MakeLoss(cl->load.graph.robust, cl->load.graph.robust_width);
    cl->load.graph.convention = ParsePoseErrorConvention(cl->convention);
    cl->load.init = slam::ParseInitMethod(cl->init);
    cl->outlier_options.mode = slam::ParseOutlierMode(cl->outlier_mode);
  } catch (const Error& e) {
    UsageError(e.what());
  }
  if (cl->certify && !cl->convention_given) {
    cl->load.graph.convention = PoseErrorConvention::kSESync;
  }
  return std::nullopt;
}

}  // namespace boxplus::g2o_cli
