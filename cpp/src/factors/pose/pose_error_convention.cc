#include "boxplus/factors/pose/pose_error_convention.h"

#include "boxplus/errors.h"

namespace boxplus {

PoseErrorConvention ParsePoseErrorConvention(const std::string& name) {
  if (name == "g2o") return PoseErrorConvention::kG2o;
  if (name == "log" || name == "gtsam" || name == "se3log" || name == "se2log") {
    return PoseErrorConvention::kLog;
  }
  if (name == "compound") return PoseErrorConvention::kCompound;
  if (name == "sesync" || name == "chordal") return PoseErrorConvention::kSESync;
  throw Error("unknown pose error convention '" + name +
              "' (expected 'g2o', 'log', 'compound' or 'sesync')");
}

const char* ToString(PoseErrorConvention c) {
  switch (c) {
    case PoseErrorConvention::kG2o:
      return "g2o";
    case PoseErrorConvention::kLog:
      return "log";
    case PoseErrorConvention::kCompound:
      return "compound";
    case PoseErrorConvention::kSESync:
      return "sesync";
  }
  return "?";
}

}  // namespace boxplus
