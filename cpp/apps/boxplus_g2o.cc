// boxplus-g2o: optimise a g2o / TORO pose-graph file from the command line.
//
//   boxplus-g2o [options] input.g2o        ('-': standard input)
//
// g2o_cli's own flags (-solver gn_var_cholmod, -robustKernel Huber, -guess,
// -summary FILE, ...) are accepted beside boxplus' (g2o_cli/g2o_flags.h).
// Reads the file strictly (errors name the file and line), builds the
// problem (see boxplus/slam/pose_graph.h), optionally re-initialises it,
// solves it with Ceres and writes the result with the file's ids and order.
// Exit codes: 0 success, 1 the solver failed, 2 bad input, usage or a failed
// write (every output is written atomically: a failed write keeps the previous
// file), 130 interrupted (Ctrl-C: the last accepted estimate is written to -o first).
#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "boxplus/certify/certify.h"
#include "boxplus/errors.h"
#include "boxplus/io/atomic_file.h"
#include "boxplus/io/g2o.h"
#include "boxplus/loss.h"
#include "boxplus/progress.h"
#include "boxplus/slam/load.h"
#include "boxplus/solver_options.h"
#include "boxplus/version.h"
#include "g2o_cli/g2o_flags.h"

namespace {

const char* kUsage = R"(usage: boxplus-g2o [options] input.g2o     ('-' reads standard input)

Optimises a pose graph in g2o format (the slam2d/slam3d tags of g2o:
VERTEX_SE2, VERTEX_XY, VERTEX_SE3:QUAT, VERTEX_TRACKXYZ, EDGE_SE2, EDGE_SE2_XY,
EDGE_SE3:QUAT, EDGE_SE3_TRACKXYZ, EDGE_SE2/SE3_OFFSET, EDGE_PRIOR_SE2,
EDGE_SE3_PRIOR, EDGE_PRIOR_SE2_XY, EDGE_SE3_XYZ_PRIOR, EDGE_PRIOR_XY,
EDGE_POINTXY(Z), EDGE_POINTXYZ_PRIOR, EDGE_SE2_POINTXY_OFFSET,
EDGE_BEARING_SE2_XY, PARAMS_SE2OFFSET, PARAMS_SE3OFFSET, FIX; --list-types)
or TORO format (VERTEX2, EDGE2, VERTEX3, EDGE3 with or without information,
EQUIV), and GTSAM's LANDMARK2 landmark lines. The gauge is fixed by the FIX lines, else by the first pose vertex
(not at all when a pose prior fixes it).

options:
  -i, --iterations N     maximum number of iterations (default 100)
  -s, --solver NAME      gn-lm (default; alias auto): Gauss-Newton with a
                         backtracking line search while its full steps hold,
                         then Levenberg-Marquardt (chosen and measured on a
                         generated suite of graphs, README "Graph SLAM"); lm
                         (Levenberg-Marquardt), gn (Gauss-Newton: undamped,
                         the trust region only rejects steps), gn-ls
                         (Gauss-Newton with a backtracking line search),
                         dogleg
  -r, --robust NAME      robust kernel: none (default), huber, cauchy, tukey,
                         arctan, softl1, dcs (dynamic covariance scaling),
                         geman_mcclure
  -w, --robust-width W   kernel width on sqrt(e'Ωe) (default 1)
      --outlier-mode NAME
                         wrong loop closures: auto (default: when the
                         least-squares solution is implausible, chi2/dof > 10,
                         judge the loop closures by graduated non-convexity
                         with truncated least squares and return the inliers'
                         optimum), gnc-tls or gnc-gm (always), off (never:
                         the lowest least-squares minimum, from several starts)
      --inlier-probability P
                         an inlier's e'Ωe is below the P-quantile of chi2(d)
                         (d = 3 in 2D, 6 in 3D; default 0.99)
      --outliers FILE    write the edges judged wrong (file line, ids, e'Ωe)
  -t, --threads N        threads for the Jacobians and the factorisation's BLAS
                         (default: the Jacobians on one, the BLAS on every
                         core; OPENBLAS_NUM_THREADS, when set, decides the
                         BLAS threads)
  -o, --output FILE      write the optimised graph (ids and order kept); '-' is
                         stdout (then every other line goes to stderr); written
                         whole or not at all, never over the input unless
      --overwrite-input  is given
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
      --gauge ID[,ID...] hold these vertices fixed (instead of the FIX lines or
                         the first vertex)
      --certify          after solving, prove the solution globally optimal or
                         not (SE-Sync's certificate: one sparse Cholesky
                         factorisation) and, if it is not, escape the saddle
                         by the Riemannian staircase and solve again (README
                         "Certified pose graphs"); implies -c sesync unless -c
                         is given, in which case the certificate is only
                         evaluated at that convention's solution
      --certify-tolerance X
                         certify when f - f* <= X f is proven (default 1e-6)
      --max-rank N       highest rank of the staircase (default 10; 2 or 3,
                         the graph's dimension, verifies only)
      --summary FILE     append one line about the run (file, sizes, chi2,
                         iterations, time, status) to FILE
      --stats FILE       write the per-iteration lines to FILE
  -q, --quiet            no per-iteration lines, no progress while loading
  -v, --verbose          per-iteration lines (the default; for g2o's -v)
      --report           print the solver's full report at the end (Ceres', or
                         gn-ls' own, naming its Cholesky and ordering)
      --list-solvers, --list-robust-kernels, --list-types
                         print the names accepted and exit
  -h, --help             this help
      --version          print the version

g2o's spellings are accepted too: -solver NAME (gn_var, lm_fix6_3_cholmod,
dl_var, ...: gn, lm or dogleg), -robustKernel NAME (Huber, Cauchy, Tukey,
PseudoHuber), -robustKernelWidth X, -guess (spanning-tree initialisation),
-gaugeId N, -gaugeList L, -summary FILE, -stats FILE, -v, -listSolvers,
-listRobustKernels, -listTypes; g2o's flags without a boxplus meaning (-inc,
-marginalize, -solverProperties, ...) are refused by name.

Output: on stdout one line per iteration in boxplus' progress format (chi2 =
sum of e'Ωe, with the robust kernel if any; twice Ceres' cost; cumulative time
in seconds); on stderr the '#' diagnostics (file, sizes, times, initial and
final chi2, memory), the summary and, while a big file loads, about once a
second a line with the lines read and the bytes of the file. Ctrl-C stops the solver after the current
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

namespace {

std::vector<int> ParseIdList(const std::string& opt, const std::string& s) {
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

void ListSolvers() {
  std::printf("boxplus methods:");
  for (const auto& m : boxplus::MethodNames()) std::printf(" %s", m.c_str());
  std::printf(
      " auto\ng2o's names: (gn|lm|dl)_(var|fixP_L)[_cholmod|_csparse|_eigen|_dense|_pcg],"
      " e.g. gn_var, lm_fix6_3_cholmod, dl_var → gn, lm, dogleg (sparse Cholesky)\n");
}

void ListRobustKernels() {
  std::printf("boxplus:");
  for (const auto& l : boxplus::LossNames()) std::printf(" %s", l.c_str());
  std::printf("\n%s\n", boxplus::g2o_cli::kG2oKernelsHelp);
}

void ListTypes() {
  std::printf(
      "g2o: VERTEX_SE2 VERTEX_XY VERTEX_SE3:QUAT VERTEX_TRACKXYZ PARAMS_SE2OFFSET "
      "PARAMS_SE3OFFSET EDGE_SE2 EDGE_SE2_XY EDGE_SE2_OFFSET EDGE_SE2_POINTXY_OFFSET "
      "EDGE_PRIOR_SE2 EDGE_PRIOR_SE2_XY EDGE_PRIOR_XY EDGE_POINTXY EDGE_BEARING_SE2_XY "
      "EDGE_SE3:QUAT EDGE_SE3_TRACKXYZ EDGE_SE3_OFFSET EDGE_SE3_PRIOR EDGE_SE3_XYZ_PRIOR "
      "EDGE_POINTXYZ EDGE_POINTXYZ_PRIOR FIX\nboxplus: EDGE_SE2_BEARING_RANGE\n"
      "TORO: VERTEX VERTEX2 EDGE EDGE2 VERTEX3 EDGE3 EQUIV\n"
      "GTSAM's example data: LANDMARK2 (= EDGE_SE2_XY)\n");
}

// CHOLMOD's supernodal factorisation runs in BLAS: --threads N gives it N
// threads, as it gives the Jacobians. Without --threads the Jacobians run on
// one thread and the BLAS on every core: a pose graph's time is mostly the
// factorisation, the supernodal one (chosen where the factor fills in) gains
// from a second core (whole runs 0.59-0.71x of one BLAS thread on sphere2500
// and generated 3D graphs of 3000 and 10^4 poses), the simplicial one never
// calls BLAS (small and sparse graphs: no change), and evaluating the terms
// on two threads did not pay (README "Graph SLAM"). A BLAS without this entry
// point, or an OPENBLAS_NUM_THREADS the user set, is left as it is.
void LimitBlasThreads(int threads) {
  if (std::getenv("OPENBLAS_NUM_THREADS") != nullptr) return;
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
    set(threads);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string input, output, solver = "auto", convention = "g2o", init = "best";
  std::string summary_file, stats_file, gauge, outliers_file, outlier_mode = "auto";
  boxplus::slam::OutlierOptions outlier_options;
  int iterations = 100, threads = 1;
  bool threads_given = false;
  bool quiet = false, full_report = false, certify = false, convention_given = false;
  bool overwrite_input = false;
  boxplus::certify::CertifyOptions certify_options;
  boxplus::slam::LoadOptions load;
  boxplus::SolverOptions so = boxplus::slam::DefaultSolverOptions();
  std::vector<std::string> args;
  try {
    args = boxplus::g2o_cli::FromG2oFlags(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::invalid_argument& e) {
    UsageError(e.what());
  }
  bool listed = false;
  for (size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    auto value = [&]() -> const char* {
      if (k + 1 >= args.size()) UsageError(a + " needs a value");
      return args[++k].c_str();
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--version") {
      std::printf("boxplus-g2o %s\n", BOXPLUS_VERSION_STRING);
      return 0;
    } else if (a == "--list-solvers") {
      ListSolvers();
      listed = true;
    } else if (a == "--list-robust-kernels") {
      ListRobustKernels();
      listed = true;
    } else if (a == "--list-types") {
      ListTypes();
      listed = true;
    } else if (a == "-i" || a == "--iterations") {
      iterations = ParseInt(a, value());
    } else if (a == "-s" || a == "--solver") {
      solver = value();
    } else if (a == "-r" || a == "--robust") {
      load.graph.robust = value();
    } else if (a == "--outlier-mode") {
      outlier_mode = value();
    } else if (a == "--inlier-probability") {
      outlier_options.inlier_probability = ParseDouble(a, value());
      if (!(outlier_options.inlier_probability > 0 && outlier_options.inlier_probability < 1)) {
        UsageError("--inlier-probability must be in (0, 1)");
      }
    } else if (a == "--outliers") {
      outliers_file = value();
    } else if (a == "-w" || a == "--robust-width") {
      load.graph.robust_width = ParseDouble(a, value());
    } else if (a == "-t" || a == "--threads") {
      threads = ParseInt(a, value());
      threads_given = true;
    } else if (a == "-o" || a == "--output") {
      output = value();
    } else if (a == "--overwrite-input") {
      overwrite_input = true;
    } else if (a == "-c" || a == "--convention") {
      convention = value();
      convention_given = true;
    } else if (a == "--certify") {
      certify = true;
    } else if (a == "--certify-tolerance") {
      certify_options.certificate.relative_tolerance = ParseDouble(a, value());
      if (!(certify_options.certificate.relative_tolerance > 0)) {
        UsageError("--certify-tolerance must be > 0");
      }
    } else if (a == "--max-rank") {
      certify_options.max_rank = ParseInt(a, value());
    } else if (a == "--init") {
      init = value();
    } else if (a == "--gauge") {
      gauge = value();
    } else if (a == "--summary") {
      summary_file = value();
    } else if (a == "--stats") {
      stats_file = value();
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
    } else if (a == "-v" || a == "--verbose") {
      quiet = false;
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
  if (listed && input.empty()) return 0;
  if (input.empty()) UsageError("no input file");
  if (threads < 1) UsageError("--threads must be >= 1");
  // A user's input is never written over without being asked: -o, --summary and
  // --stats naming the input file (through any path, link or symlink) are refused.
  for (const auto& [flag, path] : {std::pair<const char*, std::string>{"-o", output},
                                   {"--summary", summary_file},
                                   {"--outliers", outliers_file},
                                   {"--stats", stats_file}}) {
    if (!path.empty() && path != "-" && input != "-" && boxplus::io::SameFile(path, input) &&
        !(overwrite_input && std::string(flag) == "-o")) {
      UsageError(std::string(flag) + " '" + path + "' is the input file '" + input +
                 "'; write elsewhere" +
                 (std::string(flag) == "-o" ? ", or give --overwrite-input to replace it" : ""));
    }
  }
  const std::vector<int> gauge_ids =
      gauge.empty() ? std::vector<int>() : ParseIdList("--gauge", gauge);
  // The vocabulary's one parser each (solver_options.h, loss.h, the pose
  // error convention, the initialisation).
  try {
    so.method = boxplus::ParseMethod(solver);
    boxplus::MakeLoss(load.graph.robust, load.graph.robust_width);
    load.graph.convention = boxplus::ParsePoseErrorConvention(convention);
    load.init = boxplus::slam::ParseInitMethod(init);
    outlier_options.mode = boxplus::slam::ParseOutlierMode(outlier_mode);
  } catch (const boxplus::Error& e) {
    UsageError(e.what());
  }
  if (certify && !convention_given) {
    load.graph.convention = boxplus::PoseErrorConvention::kSESync;
  }
  so.max_iterations = iterations;
  so.num_threads = threads;
  LimitBlasThreads(
      threads_given ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  // With the graph on stdout, every other line goes to stderr.
  const bool graph_to_stdout = output == "-";
  FILE* progress = graph_to_stdout ? stderr : stdout;
  const std::string shown = input == "-" ? "<stdin>" : input;

  try {
    const double rss_before = MemoryMB("VmRSS");
    std::signal(SIGINT, OnSigint);
    // A line on stderr about once a second while a big file is parsed.
    using Clock = std::chrono::steady_clock;
    auto last_progress = Clock::now();
    if (!quiet) {
      load.read.on_progress = [&](const boxplus::io::ReadProgress& p) {
        const auto now = Clock::now();
        if (now - last_progress < std::chrono::seconds(1)) return;
        last_progress = now;
        std::fprintf(stderr, "# reading %s: %lld lines, %.1f of %.1f MB\n", shown.c_str(), p.lines,
                     p.bytes / 1e6, p.bytes_total / 1e6);
      };
    }
    boxplus::slam::LoadReport report;
    std::unique_ptr<boxplus::slam::PoseGraph> pg;
    if (input == "-") {
      pg = boxplus::slam::LoadPoseGraphFromText(boxplus::io::ReadTextStream(std::cin, shown), shown,
                                                load, &report);
    } else {
      pg = boxplus::slam::LoadPoseGraph(input, load, &report);
    }
    std::fputs(report.warnings.c_str(), stderr);
    if (!report.estimates_from_file && load.init == boxplus::slam::InitMethod::kFile) {
      std::fprintf(stderr, "%s: no VERTEX lines: initial estimate by spanning tree\n",
                   shown.c_str());
    }
    if (!gauge_ids.empty()) pg->SetGauge(gauge_ids);
    pg->set_outlier_options(outlier_options);
    std::fprintf(stderr,
                 "# %s: %zu vertices, %zu edges, %dD, gauge vertex %d, read %.3f s, "
                 "init %.3f s, build %.3f s\n",
                 shown.c_str(), pg->graph().vertices.size(), pg->graph().edges.size(),
                 pg->graph().dimension, pg->gauge_vertex(), report.read_s, report.init_s,
                 report.build_s);
    const double chi2_initial = pg->Chi2();
    std::fprintf(stderr, "# initial chi2 %.10g (convention %s, init %s: start %s, solver %s)\n",
                 chi2_initial, boxplus::ToString(load.graph.convention), init.c_str(),
                 report.start.c_str(), boxplus::MethodName(so.method).c_str());
    // The per-iteration lines of --stats, written (atomically) when the solve ends.
    std::string stats = boxplus::ProgressHeader() + "\n";
    if (!quiet) std::fprintf(progress, "%s\n", boxplus::ProgressHeader().c_str());
    so.on_iteration = [quiet, progress, &stats](const boxplus::IterationInfo& it) {
      if (!quiet) {
        std::fprintf(progress, "%s\n", boxplus::FormatProgress(it).c_str());
        std::fflush(progress);
      }
      stats += boxplus::FormatProgress(it) + "\n";
      return !g_interrupted.load();
    };
    const boxplus::SolveSummary s = g_interrupted ? boxplus::SolveSummary() : pg->Solve(so);
    boxplus::certify::CertifyResult cert;
    if (certify && !g_interrupted && s.usable) {
      certify_options.local.on_iteration = so.on_iteration;
      certify_options.local.num_threads = threads;
      certify_options.interrupted = [] { return g_interrupted.load(); };
      cert = boxplus::certify::CertifyPoseGraph(pg.get(), certify_options);
      std::fprintf(stderr,
                   "# certificate: %s\n# certificate: verification %.3f s, staircase and local "
                   "solves %.3f s, highest rank %d\n",
                   cert.message.c_str(), cert.verify_time_s, cert.solve_time_s,
                   cert.max_rank_reached);
    }
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
    const boxplus::slam::OutlierReport& judged = pg->outlier_report();
    if (judged.ran) {
      std::fprintf(
          stderr,
          "# outliers: %zu of %d loop closures judged wrong (%s, threshold e'Ωe > %.4g)%s\n",
          judged.outliers.size(), judged.candidates, judged.method.c_str(), judged.threshold,
          judged.outliers.empty() || !outliers_file.empty() ? "" : "; --outliers FILE lists them");
    }
    if (per_dof > boxplus::slam::kImplausibleChi2PerDof && load.graph.robust == "none" &&
        !judged.ran) {
      std::fprintf(stderr,
                   "boxplus-g2o: warning: chi2/dof = %.3g is far above 1: wrong loop closures or "
                   "overconfident information matrices? A robust kernel (-r cauchy) may help\n",
                   per_dof);
    }
    std::fprintf(stderr, "# memory: peak RSS %.1f MB, %.1f MB before reading the input\n",
                 MemoryMB("VmHWM"), rss_before);
    // Every output is written whole or not at all, and a failed write is an error
    // naming the file (io/atomic_file.h); the graph first, the most valuable one.
    bool write_failed = false;
    auto write = [&](const std::function<void()>& fn) {
      try {
        fn();
      } catch (const boxplus::Error& e) {
        std::fprintf(stderr, "boxplus-g2o: %s\n", e.what());
        write_failed = true;
      }
    };
    if (graph_to_stdout) {
      pg->WriteBack();
      write([&] {
        boxplus::io::WriteAllOrThrow(stdout, boxplus::io::FormatG2o(pg->graph()),
                                     "the graph to stdout");
      });
    } else if (!output.empty()) {
      write([&] {
        pg->Save(output);
        std::fprintf(stderr, "# wrote %s\n", output.c_str());
      });
    }
    if (!outliers_file.empty()) {
      write([&] {
        boxplus::io::WriteFileAtomically(outliers_file,
                                         boxplus::slam::FormatOutliers(judged, shown));
        std::fprintf(stderr, "# wrote %s\n", outliers_file.c_str());
      });
    }
    if (!stats_file.empty()) {
      write([&] { boxplus::io::WriteFileAtomically(stats_file, stats); });
    }
    if (!summary_file.empty()) {
      char line[2048];
      std::snprintf(line, sizeof(line),
                    "file=%s vertices=%zu edges=%zu solver=%s iterations=%d chi2_initial=%.17g "
                    "chi2_final=%.17g time_s=%.6f status=%s%s\n",
                    shown.c_str(), pg->graph().vertices.size(), pg->graph().edges.size(),
                    boxplus::MethodName(so.method).c_str(), s.iterations, chi2_initial, pg->Chi2(),
                    s.time_s,
                    g_interrupted ? "interrupted"
                    : s.usable    ? "ok"
                                  : "failed",
                    !certify         ? ""
                    : cert.certified ? " certified=1"
                                     : " certified=0");
      write([&] { boxplus::io::AppendFileAtomically(summary_file, line); });
    }
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
      std::fprintf(stderr, "boxplus-g2o: cannot write to stdout: %s\n", std::strerror(errno));
      write_failed = true;
    }
    if (write_failed) return 2;
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
