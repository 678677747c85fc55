// Camera models: intrinsics k and the projection uv = π(k, x, y) of a point
// with normalised coordinates x = X/Z, y = Y/Z (in the camera frame), and the
// rig chain every camera factor shares.
//
// One model family, uv = [fx·x', fy·y'] + [cx, cy], with the distorted
// normalised point (r² = x² + y²)
//   x' = x·rad + 2p1·xy + p2(r² + 2x²),  y' = y·rad + p1(r² + 2y²) + 2p2·xy,
//   rad = 1 + k1 r² + k2 r⁴ + k3 r⁶,
// instantiated (CameraModel<focals, radial terms, tangential>) as
//   SimpleRadial  k = [f, cx, cy, k1]          (fx = fy = f; MTKM paper, Listing 1)
//   Pinhole       k = [fx, fy, cx, cy]
//   Radial1       k = [fx, fy, cx, cy, k1]     (OpenCV: FIX_K2|FIX_K3|ZERO_TANGENT_DIST)
//   Radial2       k = [fx, fy, cx, cy, k1, k2] (OpenCV: FIX_K3|ZERO_TANGENT_DIST)
//   OpenCV5       k = [fx, fy, cx, cy, k1, k2, p1, p2, k3]  (OpenCV's default model)
// Units: f, c in pixels, k, p dimensionless. Points behind the camera still give
// a value (no branch), so Jacobians stay smooth; initialise with the board in front.
#pragma once

#include <string>

#include "boxplus/manifolds/se3.h"

namespace boxplus {

namespace camera {

[[noreturn]] void ThrowUnknownCameraModel(const std::string& name);

// kFocals: 1 (f) or 2 (fx, fy); kRadial: number of radial coefficients
// k1, k2, k3; kTangential: p1, p2 (stored between k2 and k3, OpenCV's order).
template <int kFocals, int kRadial, bool kTangential>
struct CameraModel {
  static constexpr int kSize = kFocals + 2 + kRadial + (kTangential ? 2 : 0);

  // Index in k of the radial coefficient k_{i+1}.
  static constexpr int RadialIndex(int i) {
    return kFocals + 2 + (kTangential && i >= 2 ? i + 2 : i);
  }

  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    T xd = x, yd = y;
    if constexpr (kRadial > 0) {
      const T r2 = x * x + y * y;
      // Horner: k1 r² + k2 r⁴ + k3 r⁶ = r²(k1 + r²(k2 + r² k3)).
      T poly = k[RadialIndex(kRadial - 1)] * r2;
      for (int i = kRadial - 2; i >= 0; --i) poly = r2 * (k[RadialIndex(i)] + poly);
      const T rad = T(1.0) + poly;
      xd = x * rad;
      yd = y * rad;
      if constexpr (kTangential) {
        const T& p1 = k[kFocals + 4];
        const T& p2 = k[kFocals + 5];
        xd += T(2.0) * p1 * x * y + p2 * (r2 + T(2.0) * x * x);
        yd += p1 * (r2 + T(2.0) * y * y) + T(2.0) * p2 * x * y;
      }
    }
    uv[0] = k[0] * xd + k[kFocals];
    uv[1] = k[kFocals - 1] * yd + k[kFocals + 1];
  }
};

struct SimpleRadial : CameraModel<1, 1, false> {
  static constexpr const char* kName = "simple_radial";
};
struct Pinhole : CameraModel<2, 0, false> {
  static constexpr const char* kName = "pinhole";
};
struct Radial1 : CameraModel<2, 1, false> {
  static constexpr const char* kName = "radial1";
};
struct Radial2 : CameraModel<2, 2, false> {
  static constexpr const char* kName = "radial2";
};
struct OpenCV5 : CameraModel<2, 3, true> {
  static constexpr const char* kName = "opencv5";
};

// Calls f(Model{}) with the model named `name` ("simple_radial", "pinhole",
// "radial1", "radial2", "opencv5"); throws boxplus::Error for other names.
template <class F>
auto WithCameraModel(const std::string& name, F&& f) {
  if (name == SimpleRadial::kName) return f(SimpleRadial{});
  if (name == Pinhole::kName) return f(Pinhole{});
  if (name == Radial1::kName) return f(Radial1{});
  if (name == Radial2::kName) return f(Radial2{});
  if (name == OpenCV5::kName) return f(OpenCV5{});
  ThrowUnknownCameraModel(name);
  return f(OpenCV5{});  // not reached
}

// The rig chain of every camera factor (the MTKM paper's project_point):
//   p_in_cam = cam_from_rig · world_from_rig⁻¹ · p_in_world
// "rig" is the reference camera of a rig (MTKM's x; world_from_rig is MTKM's
// x2world), cam_from_rig takes it to this camera (the identity, fixed, for a
// single camera). Poses [p, q(x,y,z,w)]: b_from_a maps a-coordinates to b.
template <typename T>
void ChainToCam(const T* world_from_rig, const T* cam_from_rig, const T* p_in_world, T* p_in_cam) {
  const T d[3] = {p_in_world[0] - world_from_rig[0], p_in_world[1] - world_from_rig[1],
                  p_in_world[2] - world_from_rig[2]};
  T rig_from_world_q[4], p_in_rig[3];
  QuatConjugate(world_from_rig + 3, rig_from_world_q);
  QuatRotatePoint(rig_from_world_q, d, p_in_rig);
  QuatRotatePoint(cam_from_rig + 3, p_in_rig, p_in_cam);
  for (int i = 0; i < 3; ++i) p_in_cam[i] += cam_from_rig[i];
}

}  // namespace camera

// Number of intrinsic parameters of a camera model named at run time.
int CameraModelSize(const std::string& model);

}  // namespace boxplus
