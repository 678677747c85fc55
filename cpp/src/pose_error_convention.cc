#include "boxplus/factors/pose_error_convention.h"

#include "boxplus/errors.h"

namespace boxplus {

PoseErrorConvention ParsePoseErrorConvention(const std::string& name) {
  if (name == "g2o") return PoseErrorConvention::kG2o;
  if (name == "log" || name == "gtsam" || name == "se3log" || name == "se2log") {
    return PoseErrorConvention::kLog;
  }
  throw Error("unknown pose error convention '" + name + "' (expected 'g2o' or 'log')");
}

const char* ToString(PoseErrorConvention c) {
  return c == PoseErrorConvention::kG2o ? "g2o" : "log";
}

}  // namespace boxplus
