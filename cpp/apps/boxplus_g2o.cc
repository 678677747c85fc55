// boxplus-g2o: optimise a g2o / TORO pose-graph file from the command line.
//
//   boxplus-g2o [options] input.g2o
//
// Reads the file strictly (errors name the file and line), builds the
// problem (see boxplus/slam/pose_graph.h), optionally re-initialises it,
// solves it with Ceres and writes the result with the file's ids and order.
// Exit codes: 0 success, 1 the solver failed, 2 bad input or usage.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "boxplus/errors.h"
#include "boxplus/io/g2o.h"
#include "boxplus/slam/initialization.h"
#include "boxplus/slam/pose_graph.h"
#include "boxplus/version.h"

namespace {

const char* kUsage = R"(usage: boxplus-g2o [options] input.g2o

Optimises a pose graph in g2o format (VERTEX_SE2, EDGE_SE2, VERTEX_XY,
EDGE_SE2_XY, VERTEX_SE3:QUAT, EDGE_SE3:QUAT, VERTEX_TRACKXYZ,
EDGE_SE3_TRACKXYZ, FIX) or TORO format (VERTEX2, EDGE2, VERTEX3, EDGE3).
The gauge is fixed by the FIX lines, else by the first vertex.

options:
  -i, --iterations N     maximum number of iterations (default 100)
  -s, --solver NAME      auto (default: dogleg for 2D graphs, lm for 3D, as
                         measured on the standard data sets), lm
                         (Levenberg-Marquardt), gn (Gauss-Newton: undamped,
                         the trust region only rejects steps), gn-ls
                         (Gauss-Newton with a backtracking line search;
                         single-threaded), dogleg
  -r, --robust NAME      robust kernel: none (default), huber, cauchy, tukey,
                         arctan, softl1
  -w, --robust-width W   kernel width on sqrt(e'Ωe) (default 1)
  -t, --threads N        threads for Jacobians and linear algebra (default 1)
  -o, --output FILE      write the optimised graph (ids and order kept)
  -c, --convention NAME  pose error: g2o (default; [t, vec(q)] of z⁻¹xᵢ⁻¹xⱼ, as
                         g2o's EdgeSE2/3), log (GTSAM's Pose2/Pose3 Logmap) or
                         sesync (alias chordal: SE-Sync's objective
                         Σ κ‖Rj − Ri R̃ij‖²_F + τ‖tj − ti − Ri t̃ij‖²)
      --init NAME        file (default), spanning-tree, chordal
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

Output: one line per iteration (chi2 = sum of e'Ωe, with the robust kernel if
any; time in seconds), then a summary. chi2 is twice Ceres' cost.
)";

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
  std::string input, output, solver = "auto", robust = "none", convention = "g2o",
                            init = "file";
  double width = 1.0;
  int iterations = 100, threads = 1;
  bool quiet = false, full_report = false;
  boxplus::io::ReadOptions read;
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
      robust = value();
    } else if (a == "-w" || a == "--robust-width") {
      width = ParseDouble(a, value());
    } else if (a == "-t" || a == "--threads") {
      threads = ParseInt(a, value());
    } else if (a == "-o" || a == "--output") {
      output = value();
    } else if (a == "-c" || a == "--convention") {
      convention = value();
    } else if (a == "--init") {
      init = value();
    } else if (a == "--skip-unknown") {
      read.skip_unknown_tags = true;
    } else if (a == "--repair-information") {
      read.repair_information = true;
    } else if (a == "--initial-radius") {
      so.initial_trust_region_radius = ParseDouble(a, value());
      if (!(so.initial_trust_region_radius > 0)) UsageError("--initial-radius must be > 0");
    } else if (a == "--damping") {
      const std::string d = value();
      if (d == "marquardt") {
        so.damping = boxplus::Damping::kMarquardt;
      } else if (d == "levenberg") {
        so.damping = boxplus::Damping::kLevenberg;
      } else {
        UsageError("unknown damping '" + d + "' (marquardt or levenberg)");
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
    } else if (!a.empty() && a[0] == '-') {
      UsageError("unknown option " + a);
    } else if (input.empty()) {
      input = a;
    } else {
      UsageError("more than one input file ('" + input + "', '" + a + "')");
    }
  }
  if (input.empty()) UsageError("no input file");
  if (threads < 1) UsageError("--threads must be >= 1");
  if (solver == "lm") {
    so.method = boxplus::Method::kLevenbergMarquardt;
  } else if (solver == "gn") {
    so.method = boxplus::Method::kGaussNewton;
  } else if (solver == "dogleg") {
    so.method = boxplus::Method::kDogleg;
  } else if (solver == "gn-ls" || solver == "gn_ls") {
    so.method = boxplus::Method::kGaussNewtonLineSearch;
  } else if (solver != "auto") {
    UsageError("unknown solver '" + solver + "' (auto, lm, gn, gn-ls or dogleg)");
  }
  so.max_iterations = iterations;
  so.num_threads = threads;

  try {
    const double rss_before = MemoryMB("VmRSS");
    const auto t0 = std::chrono::steady_clock::now();
    boxplus::io::ReadReport report;
    boxplus::io::Graph graph = boxplus::io::ReadG2o(input, read, &report);
    std::fputs(report.Warnings(input).c_str(), stderr);
    boxplus::slam::PoseGraphOptions po;
    po.convention = boxplus::ParsePoseErrorConvention(convention);
    po.robust = robust;
    po.robust_width = width;
    const boxplus::slam::InitMethod im = boxplus::slam::ParseInitMethod(init);
    if (!graph.estimates_from_file && im == boxplus::slam::InitMethod::kFile) {
      std::fprintf(stderr, "%s: no VERTEX lines: initial estimate by spanning tree\n",
                   input.c_str());
    }
    boxplus::slam::Initialize(&graph, im);
    const auto t_read = std::chrono::steady_clock::now();
    if (solver == "auto") so.method = boxplus::slam::DefaultMethod(graph.dimension);
    boxplus::slam::PoseGraph pg(std::move(graph), po);
    const auto t_built = std::chrono::steady_clock::now();
    const double read_s = std::chrono::duration<double>(t_read - t0).count();
    const double build_s = std::chrono::duration<double>(t_built - t_read).count();
    std::printf("# %s: %zu vertices, %zu edges, %dD, gauge vertex %d, read %.3f s, build %.3f s\n",
                input.c_str(), pg.graph().vertices.size(), pg.graph().edges.size(),
                pg.graph().dimension, pg.gauge_vertex(), read_s, build_s);
    std::printf("# initial chi2 %.10g (convention %s, init %s)\n", pg.Chi2(),
                boxplus::ToString(po.convention), init.c_str());
    if (!quiet) {
      // The line search reports its step length α where the trust region
      // reports its radius.
      const char* radius = so.method == boxplus::Method::kGaussNewtonLineSearch ? "alpha" : "radius";
      so.on_iteration = [radius](const boxplus::IterationInfo& it) {
        std::printf("iteration= %d\t chi2= %.10g\t time= %.6f\t cumTime= %.6f\t "
                    "|grad|= %.3e\t |step|= %.3e\t %s= %.3e%s\n",
                    it.iteration, 2.0 * it.cost, it.iteration_time_s, it.cumulative_time_s,
                    it.gradient_max_norm, it.step_norm, radius, it.trust_region_radius,
                    it.step_is_successful ? "" : "\t (rejected)");
        std::fflush(stdout);
        return true;
      };
    }
    const boxplus::SolveSummary s = pg.Solve(so);
    if (full_report) std::printf("%s\n", s.report.c_str());
    std::printf("# %s after %d iterations, %.6f s: chi2 %.10g -> %.10g (%s); %s\n",
                s.termination.c_str(), s.iterations, s.time_s, 2.0 * s.initial_cost,
                2.0 * s.final_cost, robust == "none" ? "no robust kernel" : robust.c_str(),
                s.message.c_str());
    std::printf("# final chi2 g2o convention %.10g, log convention %.10g, sesync %.10g\n",
                pg.Chi2(boxplus::PoseErrorConvention::kG2o),
                pg.Chi2(boxplus::PoseErrorConvention::kLog),
                pg.Chi2(boxplus::PoseErrorConvention::kSESync));
    std::printf("# memory: peak RSS %.1f MB, %.1f MB before reading the input\n",
                MemoryMB("VmHWM"), rss_before);
    if (!output.empty()) {
      pg.Save(output);
      std::printf("# wrote %s\n", output.c_str());
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
