#include "boxplus/slam/load.h"

#include <chrono>

#include "boxplus/errors.h"

namespace boxplus::slam {

namespace {

// Reads with `read` (the file or the text), then initialises and builds.
template <typename Read>
std::unique_ptr<PoseGraph> Load(const std::string& name, const LoadOptions& options,
                                LoadReport* report, Read read) {
  using Clock = std::chrono::steady_clock;
  LoadReport local;
  LoadReport& rep = report ? *report : local;
  rep = LoadReport();
  const auto t0 = Clock::now();
  io::Graph graph = read(&rep.read);
  rep.warnings = rep.read.Warnings(name);
  BOXPLUS_CHECK(!graph.vertices.empty(), io::Escaped(name),
                ": no vertex or edge lines (an empty or comment-only file)");
  rep.estimates_from_file = graph.estimates_from_file;
  const auto t1 = Clock::now();
  std::vector<Eigen::VectorXd> second_start;
  rep.start = InitMethodName(Initialize(
      &graph, options.init, -1, [&](const io::Graph& g) { return Objective(g, options.graph); },
      &second_start));
  const auto t2 = Clock::now();
  auto pg = std::make_unique<PoseGraph>(std::move(graph), options.graph);
  pg->set_second_start(std::move(second_start));
  pg->set_restart_when_implausible(options.init == InitMethod::kBest);
  const auto t3 = Clock::now();
  rep.read_s = std::chrono::duration<double>(t1 - t0).count();
  rep.init_s = std::chrono::duration<double>(t2 - t1).count();
  rep.build_s = std::chrono::duration<double>(t3 - t2).count();
  return pg;
}

}  // namespace

std::unique_ptr<PoseGraph> LoadPoseGraph(const std::string& path, const LoadOptions& options,
                                         LoadReport* report) {
  return Load(path, options, report,
              [&](io::ReadReport* r) { return io::ReadG2o(path, options.read, r); });
}

std::unique_ptr<PoseGraph> LoadPoseGraphFromText(const std::string& text, const std::string& name,
                                                 const LoadOptions& options, LoadReport* report) {
  return Load(name, options, report,
              [&](io::ReadReport* r) { return io::ParseG2o(text, name, options.read, r); });
}

}  // namespace boxplus::slam
