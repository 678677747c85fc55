#include "boxplus/slam/load.h"

#include <chrono>

#include "boxplus/errors.h"

namespace boxplus::slam {

std::unique_ptr<PoseGraph> LoadPoseGraph(const std::string& path, const LoadOptions& options,
                                         LoadReport* report) {
  using Clock = std::chrono::steady_clock;
  LoadReport local;
  LoadReport& rep = report ? *report : local;
  rep = LoadReport();
  const auto t0 = Clock::now();
  io::Graph graph = io::ReadG2o(path, options.read, &rep.read);
  rep.warnings = rep.read.Warnings(path);
  BOXPLUS_CHECK(!graph.vertices.empty(), io::Escaped(path),
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
  const auto t3 = Clock::now();
  rep.read_s = std::chrono::duration<double>(t1 - t0).count();
  rep.init_s = std::chrono::duration<double>(t2 - t1).count();
  rep.build_s = std::chrono::duration<double>(t3 - t2).count();
  return pg;
}

}  // namespace boxplus::slam
