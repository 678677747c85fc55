#include "boxplus/factors/camera/models.h"

#include <iterator>

#include "boxplus/errors.h"

namespace boxplus {

namespace camera {
void ThrowUnknownCameraModel(const std::string& name) {
  std::string known;
  for (const char* m : kCameraModelNames) known += (known.empty() ? "" : ", ") + std::string(m);
  throw Error("unknown camera model '" + name + "' (expected one of " + known + ")");
}

int CameraModelIndex(const std::string& name) {
  for (size_t i = 0; i < std::size(kCameraModelNames); ++i) {
    if (name == kCameraModelNames[i]) return static_cast<int>(i);
  }
  ThrowUnknownCameraModel(name);
}
}  // namespace camera

int CameraModelSize(const std::string& model) {
  return camera::WithCameraModel(model, [](auto m) { return decltype(m)::kSize; });
}

}  // namespace boxplus
