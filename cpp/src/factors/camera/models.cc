#include "boxplus/factors/camera/models.h"

#include "boxplus/errors.h"

namespace boxplus {

namespace camera {
void ThrowUnknownCameraModel(const std::string& name) {
  throw Error("unknown camera model '" + name +
              "' (expected simple_radial, pinhole, radial1, radial2, opencv5, rational, "
              "kannala_brandt or double_sphere)");
}
}  // namespace camera

int CameraModelSize(const std::string& model) {
  return camera::WithCameraModel(model, [](auto m) { return decltype(m)::kSize; });
}

}  // namespace boxplus
