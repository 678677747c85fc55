// What slam::LoadPoseGraph did (kept by the PoseGraph it built).
#pragma once

#include <string>

#include "boxplus/io/g2o.h"

namespace boxplus::slam {

// What loading did: the reader's counts, its warnings (one line each, "" if
// none), whether the estimates came from the file (false: no VERTEX lines,
// initialised by spanning tree), the start used and the times of the three steps.
struct LoadReport {
  io::ReadReport read;
  std::string warnings;
  bool estimates_from_file = true;
  // The start the solve begins from: "file", "spanning-tree" or "chordal"
  // (what InitMethod::kBest chose, or the method asked for).
  std::string start = "file";
  double read_s = 0.0, init_s = 0.0, build_s = 0.0;
};

}  // namespace boxplus::slam
