#include "boxplus/factors/pose/pose_error_convention.h"

#include "boxplus/named_enum.h"

namespace boxplus {

namespace {

const NamedEnum<PoseErrorConvention>& Conventions() {
  static const NamedEnum<PoseErrorConvention> names(
      "pose error convention", {{PoseErrorConvention::kG2o, "g2o", {}},
                                {PoseErrorConvention::kLog, "log", {"gtsam", "se3log", "se2log"}},
                                {PoseErrorConvention::kCompound, "compound", {}},
                                {PoseErrorConvention::kSESync, "sesync", {"chordal"}}});
  return names;
}

}  // namespace

PoseErrorConvention ParsePoseErrorConvention(const std::string& name) {
  return Conventions().Parse(name);
}

const char* ToString(PoseErrorConvention c) { return Conventions().Name(c).c_str(); }

}  // namespace boxplus
