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
#include "g2o_cli/command_line.h"

namespace {

// Set by SIGINT, read by the solver's per-iteration callback: the solve stops
// at the next iteration boundary with the last accepted estimate in place.
std::atomic<bool> g_interrupted{false};
extern "C" void OnSigint(int) { g_interrupted = true; }

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

// What a run leaves for the output files.
struct RunRecord {
  const std::string& shown;  // the input's name in messages ('<stdin>' for '-')
  const std::string& stats;  // the per-iteration lines
  double chi2_initial;
  const boxplus::SolveSummary& summary;
  const boxplus::certify::CertifyResult& cert;
};

// Writes the files the command line asks for; false when a write failed (each
// failure is named on stderr). Every output is written whole or not at all
// (io/atomic_file.h); the graph first, the most valuable one.
bool WriteOutputs(const boxplus::g2o_cli::CommandLine& cl, boxplus::slam::PoseGraph* pg,
                  const RunRecord& r) {
  bool write_failed = false;
  auto write = [&](const std::function<void()>& fn) {
    try {
      fn();
    } catch (const boxplus::Error& e) {
      std::fprintf(stderr, "boxplus-g2o: %s\n", e.what());
      write_failed = true;
    }
  };
  if (cl.output == "-") {
    pg->WriteBack();
    write([&] {
      boxplus::io::WriteAllOrThrow(stdout, boxplus::io::FormatG2o(pg->graph()),
                                   "the graph to stdout");
    });
  } else if (!cl.output.empty()) {
    write([&] {
      pg->Save(cl.output);
      std::fprintf(stderr, "# wrote %s\n", cl.output.c_str());
    });
  }
  if (!cl.outliers_file.empty()) {
    write([&] {
      boxplus::io::WriteFileAtomically(
          cl.outliers_file, boxplus::slam::FormatOutliers(pg->outlier_report(), r.shown));
      std::fprintf(stderr, "# wrote %s\n", cl.outliers_file.c_str());
    });
  }
  if (!cl.stats_file.empty()) {
    write([&] { boxplus::io::WriteFileAtomically(cl.stats_file, r.stats); });
  }
  if (!cl.summary_file.empty()) {
    char line[2048];
    std::snprintf(line, sizeof(line),
                  "file=%s vertices=%zu edges=%zu solver=%s iterations=%d chi2_initial=%.17g "
                  "chi2_final=%.17g time_s=%.6f status=%s%s\n",
                  r.shown.c_str(), pg->graph().vertices.size(), pg->graph().edges.size(),
                  boxplus::MethodName(cl.solver_options.method).c_str(), r.summary.iterations,
                  r.chi2_initial, pg->Chi2(), r.summary.time_s,
                  g_interrupted      ? "interrupted"
                  : r.summary.usable ? "ok"
                                     : "failed",
                  !cl.certify        ? ""
                  : r.cert.certified ? " certified=1"
                                     : " certified=0");
    write([&] { boxplus::io::AppendFileAtomically(cl.summary_file, line); });
  }
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "boxplus-g2o: cannot write to stdout: %s\n", std::strerror(errno));
    write_failed = true;
  }
  return !write_failed;
}

}  // namespace

int main(int argc, char** argv) {
  boxplus::g2o_cli::CommandLine cl;
  if (const auto exit_code = boxplus::g2o_cli::ParseCommandLine(argc, argv, &cl)) {
    return *exit_code;
  }
  const std::string& input = cl.input;
  const std::string& output = cl.output;
  boxplus::slam::LoadOptions& load = cl.load;
  boxplus::SolverOptions& so = cl.solver_options;
  LimitBlasThreads(cl.threads_given
                       ? cl.threads
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
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
    if (!cl.quiet) {
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
    if (!cl.gauge.empty()) pg->SetGauge(cl.gauge);
    pg->set_outlier_options(cl.outlier_options);
    std::fprintf(stderr,
                 "# %s: %zu vertices, %zu edges, %dD, gauge vertex %d, read %.3f s, "
                 "init %.3f s, build %.3f s\n",
                 shown.c_str(), pg->graph().vertices.size(), pg->graph().edges.size(),
                 pg->graph().dimension, pg->gauge_vertex(), report.read_s, report.init_s,
                 report.build_s);
    const double chi2_initial = pg->Chi2();
    std::fprintf(stderr, "# initial chi2 %.10g (convention %s, init %s: start %s, solver %s)\n",
                 chi2_initial, boxplus::ToString(load.graph.convention), cl.init.c_str(),
                 report.start.c_str(), boxplus::MethodName(so.method).c_str());
    // The per-iteration lines of --stats, written (atomically) when the solve ends.
    std::string stats = boxplus::ProgressHeader() + "\n";
    if (!cl.quiet) std::fprintf(progress, "%s\n", boxplus::ProgressHeader().c_str());
    so.on_iteration = [quiet = cl.quiet, progress, &stats](const boxplus::IterationInfo& it) {
      if (!quiet) {
        std::fprintf(progress, "%s\n", boxplus::FormatProgress(it).c_str());
        std::fflush(progress);
      }
      stats += boxplus::FormatProgress(it) + "\n";
      return !g_interrupted.load();
    };
    const boxplus::SolveSummary s = g_interrupted ? boxplus::SolveSummary() : pg->Solve(so);
    boxplus::certify::CertifyResult cert;
    if (cl.certify && !g_interrupted && s.usable) {
      cl.certify_options.local.on_iteration = so.on_iteration;
      cl.certify_options.local.num_threads = cl.threads;
      cl.certify_options.interrupted = [] { return g_interrupted.load(); };
      cert = boxplus::certify::CertifyPoseGraph(pg.get(), cl.certify_options);
      std::fprintf(stderr,
                   "# certificate: %s\n# certificate: verification %.3f s, staircase and local "
                   "solves %.3f s, highest rank %d\n",
                   cert.message.c_str(), cert.verify_time_s, cert.solve_time_s,
                   cert.max_rank_reached);
    }
    if (cl.full_report) std::fprintf(stderr, "%s\n", s.report.c_str());
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
          judged.outliers.empty() || !cl.outliers_file.empty() ? ""
                                                               : "; --outliers FILE lists them");
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
    const bool write_failed = !WriteOutputs(cl, pg.get(), {shown, stats, chi2_initial, s, cert});
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
