// One way from a file to a pose graph, for the command line and Python alike:
// read (io::ReadG2o, strict unless the options relax it) → initialise
// (slam::Initialize) → build (slam::PoseGraph).
#pragma once

#include <memory>
#include <string>

#include "boxplus/io/g2o.h"
#include "boxplus/slam/initialization.h"
#include "boxplus/slam/pose_graph.h"

namespace boxplus::slam {

struct LoadOptions {
  io::ReadOptions read;
  PoseGraphOptions graph;
  InitMethod init = InitMethod::kFile;
};

// Throws boxplus::ParseError naming the file and line on malformed input, and
// boxplus::Error naming the file for errors without a line (a directory, an
// empty or comment-only file, a graph that cannot be initialised).
std::unique_ptr<PoseGraph> LoadPoseGraph(const std::string& path, const LoadOptions& options = {},
                                         LoadReport* report = nullptr);
// The same from the text of a file (standard input: boxplus-g2o -); `name`
// names it in messages.
std::unique_ptr<PoseGraph> LoadPoseGraphFromText(const std::string& text, const std::string& name,
                                                 const LoadOptions& options = {},
                                                 LoadReport* report = nullptr);

}  // namespace boxplus::slam
