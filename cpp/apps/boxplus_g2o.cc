// boxplus-g2o: optimise a g2o / TORO pose-graph file from the command line.
//
//   boxplus-g2o [options] input.g2o
//
// Reads the file strictly (errors name the file and line), builds the
// problem (see boxplus/slam/pose_graph.h), optionally re-initialises it,
// solves it with Ceres and writes the result with the file's ids and order.
// Exit codes: 0 success, 1 the solver failed, 2 bad input or usage, 130
// interrupted (Ctrl-C: the last accepted estimate is written to -o first).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "boxplus/errors.h"
#include "boxplus/io/g2o.h"
#include "boxplus/loss.h"
#include "boxplus/progress.h"
#include "boxplus/slam/load.h"
#include "boxplus/solver_options.h"
#include "boxplus/version.h"

namespace {

const char* kUsage = R"(usage: boxplus-g2o [options] input.g2o

Optimises a pose graph in g2o format (VERTEX_SE2, EDGE_SE2, VERTEX_XY,
EDGE_SE2_XY, VERTEX_SE3:QUAT, EDGE_SE3:QUAT, VERTEX_TRACKXYZ,
EDGE_SE3_TRACKXYZ, FIX) or TORO format (VERTEX2, EDGE2, VERTEX3, EDGE3).
The gauge is fixed by the FIX lines, else by the first vertex.

options:
  -i, --iterations N     maximum number of iterations (default 100)
  -s, --solver NAME      gn-lm (default; alias auto): Gauss-Newton with a
                         backtracking line search while its full steps hold,
                         then Levenberg-Marquardt (chosen on a generated suite
                         of 60 graphs, README "Pose graphs"); lm
                         (Levenberg-Marquardt), gn (Gauss-Newton: undamped,
                         the trust region only rejects steps), gn-ls
                         (Gauss-Newton with a backtracking line search;
                         single-threaded), dogleg
  -r, --robust NAME      robust kernel: none (default), huber, cauchy, tukey,
                         arctan, softl1
  -w, --robust-width W   kernel width on sqrt(e'Ωe) (default 1)
  -t, --threads N        threads for Jacobians and linear algebra (default 1)
  -o, --output FILE      write the optimised graph (ids and order kept); '-' is
                         stdout (then every other line goes to stderr)
  -c, --convention NAME  pose error: g2o (default; [t, vec(q)] of z⁻¹xᵢ⁻¹xⱼ, as
                         g2o's EdgeSE2/3), log (GTSAM's Pose2/Pose3 Logmap) or
                         sesync (alias chordal: SE-Sync's objective
                         Σ κ‖Rj − Ri R̃ij‖²_F + τ‖tj − ti − Ri t̃ij‖²)
      --init NAME        best (default: the file's estimate or the chordal
                         relaxation, whichever has the lower chi2), file,
                         spanning-tree, chordal
      --skip-unknown     skip lines with unknown tags (counted in a warning)
      --repair-information
                         replace information matrices that are not positive
                         definite by the nearest positive-definite one
                         (counted in a warning)
      --initial-radius X initial trust-region radius of lm and dogleg (default
                         1e16: lm starts as Gauss-Newton and damps only after a
                         step fails; Ceres' own default is 1e4)
      --damping NAME     lm's damping: levenberg (lambda*I, as g2o's LM;
                         default) or marquardt (diag(J'J), Ceres' default)
      --jacobi-scaling   scale the columns of J by 1/(1+|J_k|) (Ceres' default;
                         off by default here)
      --nonmonotonic N   accept up to N consecutive cost increases while the
                         best cost still decreases (default 5; 0: monotonic)
      --function-tolerance X, --gradient-tolerance X, --parameter-tolerance X
                         Ceres' stopping tolerances (defaults 1e-10, 1e-12, 1e-10)
  -q, --quiet            no per-iteration lines
      --report           print Ceres' full report at the end
  -h, --help             this help
      --version          print the version

Output: on stdout one line per iteration in boxplus' progress format (chi2 =
sum of e'Ωe, with the robust kernel if any; twice Ceres' cost; cumulative time
in seconds); on stderr the '#' diagnostics (file, sizes, times, initial and
final chi2, memory) and the summary. Ctrl-C stops the solver after the current
iteration, writes the last accepted estimate to -o and exits with 130.
)";

// Set by SIGINT, read by the solver's per-iteration callback: the solve stops
// at the next iteration boundary with the last accepted estimate in place.
std::atomic<bool> g_interrupted{false};
extern "C" void OnSigint(int) { g_interrupted = true; }

[[noreturn]] void UsageError(const std::string& what) {
  std::fprintf(stderr, "boxplus-g2o: %s\n(try boxplus-g2o --help)\n", what.c_str());
  std::exit(2);
}

double ParseDouble(const std::string& opt, const char* s) {
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0') UsageError(opt + ": not a number: '" + s + "'");
  return v;
}

int ParseInt(const std::string& opt, const char* s) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (end == s || *end != '\0' || v < 0 || v > 1000000000) {
    UsageError(opt + ": not a non-negative integer: '" + s + "'");
  }
  return static_cast<int>(v);
}

}  // namespace

// Resident memory in MB from /proc/self/status (Linux; −1 elsewhere): "VmRSS"
// now, or "VmHWM" its peak. getrusage's ru_maxrss is no use here: after exec it
// keeps the peak of the process that forked this one (a Python benchmark).
double MemoryMB(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::string key = std::string(field) + ":";
  while (std::getline(status, line)) {
    if (line.compare(0, key.size(), key) == 0) return std::atof(line.c_str() + key.size()) / 1024.0;
  }
  return -1.0;
}

int main(int argc, char** argv) {
  std::string input, output, solver = "auto", convention = "g2o", init = "best";
  int iterations = 100, threads = 1;
  bool quiet = false, full_report = false;
  boxplus::slam::LoadOptions load;
  boxplus::SolverOptions so = boxplus::slam::DefaultSolverOptions();
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto value = [&]() -> const char* {
      if (k + 1 >= argc) UsageError(a + " needs a value");
      return argv[++k];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--version") {
      std::printf("boxplus-g2o %s\n", BOXPLUS_VERSION_STRING);
      return 0;
    } else if (a == "-i" || a == "--iterations") {
      iterations = ParseInt(a, value());
    } else if (a == "-s" || a == "--solver") {
      solver = value();
    } else if (a == "-r" || a == "--robust") {
      load.graph.robust = value();
    } else if (a == "-w" || a == "--robust-width") {
      load.graph.robust_width = ParseDouble(a, value());
    } else if (a == "-t" || a == "--threads") {
      threads = ParseInt(a, value());
    } else if (a == "-o" || a == "--output") {
      output = value();
    } else if (a == "-c" || a == "--convention") {
      convention = value();
    } else if (a == "--init") {
      init = value();
    } else if (a == "--skip-unknown") {
      load.read.skip_unknown_tags = true;
    } else if (a == "--repair-information") {
      load.read.repair_information = true;
    } else if (a == "--initial-radius") {
      so.initial_trust_region_radius = ParseDouble(a, value());
      if (!(so.initial_trust_region_radius > 0)) UsageError("--initial-radius must be > 0");
    } else if (a == "--damping") {
      const std::string d = value();
      try {
        so.damping = boxplus::ParseDamping(d);
      } catch (const boxplus::Error& e) {
        UsageError(e.what());
      }
    } else if (a == "--jacobi-scaling") {
      so.jacobi_scaling = true;
    } else if (a == "--no-jacobi-scaling") {
      so.jacobi_scaling = false;
    } else if (a == "--nonmonotonic") {
      const int n = ParseInt(a, value());
      so.use_nonmonotonic_steps = n > 0;
      so.max_consecutive_nonmonotonic_steps = n;
    } else if (a == "--function-tolerance") {
      so.function_tolerance = ParseDouble(a, value());
    } else if (a == "--gradient-tolerance") {
      so.gradient_tolerance = ParseDouble(a, value());
    } else if (a == "--parameter-tolerance") {
      so.parameter_tolerance = ParseDouble(a, value());
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (a == "--report") {
      full_report = true;
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      UsageError("unknown option " + a);
    } else if (input.empty()) {
      input = a;
    } else {
      UsageError("more than one input file ('" + input + "', '" + a + "')");
    }
  }
  if (input.empty()) UsageError("no input file");
  if (threads < 1) UsageError("--threads must be >= 1");
  // The vocabulary's one parser each (solver_options.h, loss.h, the pose
  // error convention, the initialisation); "auto" is this tool's own.
  try {
    so.method = boxplus::ParseMethod(solver);
    boxplus::MakeLoss(load.graph.robust, load.graph.robust_width);
    load.graph.convention = boxplus::ParsePoseErrorConvention(convention);
    load.init = boxplus::slam::ParseInitMethod(init);
  } catch (const boxplus::Error& e) {
    UsageError(e.what());
  }
  so.max_iterations = iterations;
  so.num_threads = threads;
  // With the graph on stdout, every other line goes to stderr.
  const bool graph_to_stdout = output == "-";
  FILE* progress = graph_to_stdout ? stderr : stdout;

  try {
    const double rss_before = MemoryMB("VmRSS");
    std::signal(SIGINT, OnSigint);
    boxplus::slam::LoadReport report;
    std::unique_ptr<boxplus::slam::PoseGraph> pg =
        boxplus::slam::LoadPoseGraph(input, load, &report);
    std::fputs(report.warnings.c_str(), stderr);
    if (!report.estimates_from_file && load.init == boxplus::slam::InitMethod::kFile) {
      std::fprintf(stderr, "%s: no VERTEX lines: initial estimate by spanning tree\n",
                   input.c_str());
    }
    std::fprintf(stderr,
                 "# %s: %zu vertices, %zu edges, %dD, gauge vertex %d, read %.3f s, "
                 "init %.3f s, build %.3f s\n",
                 input.c_str(), pg->graph().vertices.size(), pg->graph().edges.size(),
                 pg->graph().dimension, pg->gauge_vertex(), report.read_s, report.init_s,
                 report.build_s);
    std::fprintf(stderr, "# initial chi2 %.10g (convention %s, init %s: start %s, solver %s)\n",
                 pg->Chi2(), boxplus::ToString(load.graph.convention), init.c_str(),
                 report.start.c_str(), boxplus::MethodName(so.method).c_str());
    if (!quiet) std::fprintf(progress, "%s\n", boxplus::ProgressHeader().c_str());
    so.on_iteration = [quiet, progress](const boxplus::IterationInfo& it) {
      if (!quiet) {
        std::fprintf(progress, "%s\n", boxplus::FormatProgress(it).c_str());
        std::fflush(progress);
      }
      return !g_interrupted.load();
    };
    const boxplus::SolveSummary s = g_interrupted ? boxplus::SolveSummary() : pg->Solve(so);
    if (full_report) std::fprintf(stderr, "%s\n", s.report.c_str());
    std::fprintf(stderr, "# %s (%s)%s\n", boxplus::FormatSummary(s).c_str(),
                 load.graph.robust == "none" ? "no robust kernel" : load.graph.robust.c_str(),
                 s.message.empty() ? "" : ("; " + s.message).c_str());
    std::fprintf(stderr, "# final chi2 g2o convention %.10g, log convention %.10g, sesync %.10g\n",
                 pg->Chi2(boxplus::PoseErrorConvention::kG2o),
                 pg->Chi2(boxplus::PoseErrorConvention::kLog),
                 pg->Chi2(boxplus::PoseErrorConvention::kSESync));
    const double per_dof = pg->Chi2PerDof();
    std::fprintf(stderr,
                 "# chi2/dof %.4g (degrees of freedom: residuals - free tangent dimensions)\n",
                 per_dof);
    if (per_dof > boxplus::slam::kImplausibleChi2PerDof && load.graph.robust == "none") {
      std::fprintf(stderr,
                   "boxplus-g2o: warning: chi2/dof = %.3g is far above 1: wrong loop closures or "
                   "overconfident information matrices? A robust kernel (-r cauchy) may help\n",
                   per_dof);
    }
    std::fprintf(stderr, "# memory: peak RSS %.1f MB, %.1f MB before reading the input\n",
                 MemoryMB("VmHWM"), rss_before);
    if (graph_to_stdout) {
      pg->WriteBack();
      const std::string text = boxplus::io::FormatG2o(pg->graph());
      std::fwrite(text.data(), 1, text.size(), stdout);
      std::fflush(stdout);
    } else if (!output.empty()) {
      pg->Save(output);
      std::fprintf(stderr, "# wrote %s\n", output.c_str());
    }
    if (g_interrupted) {
      std::fprintf(stderr, "boxplus-g2o: interrupted: %s the last accepted estimate\n",
                   output.empty() ? "not writing (no -o)" : "wrote");
      return 130;
    }
    if (!s.usable) {
      std::fprintf(stderr, "boxplus-g2o: the solver failed: %s\n", s.message.c_str());
      return 1;
    }
    return 0;
  } catch (const boxplus::Error& e) {
    std::fprintf(stderr, "boxplus-g2o: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boxplus-g2o: error: %s\n", e.what());
    return 2;
  }
}
