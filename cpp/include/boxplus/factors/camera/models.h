// Camera models: intrinsics k and the projection uv = π(k, p_in_cam) of a
// point p_in_cam = (X, Y, Z) in the camera frame, and the rig chain every
// camera factor shares. Every model has `kSize`, `kName` and
// `template <typename T> static void ProjectPoint(const T* k, const T* p, T* uv)` and
// its inverse `Unproject(k, uv, ray)` (a ray through the pixel, any length);
// the factors are templates over the model, so each model below serves every
// camera factor (point, board, marker, DH marker).
//
// 1. Pinhole with Brown–Conrady distortion of x = X/Z, y = Y/Z. One family, uv = [fx·x', fy·y'] +
// [cx, cy], with the distorted normalised point (r² = x² + y²)
//   x' = x·rad + 2p1·xy + p2(r² + 2x²),  y' = y·rad + p1(r² + 2y²) + 2p2·xy,
//   rad = 1 + k1 r² + k2 r⁴ + k3 r⁶,
// instantiated (CameraModel<focals, radial terms, tangential>) as
//   SimpleRadial  k = [f, cx, cy, k1]          (fx = fy = f; MTKM paper, Listing 1)
//   Pinhole       k = [fx, fy, cx, cy]
//   Radial1       k = [fx, fy, cx, cy, k1]     (OpenCV: FIX_K2|FIX_K3|ZERO_TANGENT_DIST)
//   Radial2       k = [fx, fy, cx, cy, k1, k2] (OpenCV: FIX_K3|ZERO_TANGENT_DIST)
//   OpenCV5       k = [fx, fy, cx, cy, k1, k2, p1, p2, k3]  (OpenCV's default model)
//   Rational      k = [fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6]
//                 (OpenCV's CALIB_RATIONAL_MODEL: rad = (1 + k1 r² + k2 r⁴ + k3 r⁶)
//                  / (1 + k4 r² + k5 r⁴ + k6 r⁶), the tangential terms as above)
// 2. KannalaBrandt k = [fx, fy, cx, cy, k1, k2, k3, k4] (OpenCV's cv2.fisheye
//    with zero skew, Kalibr's "equidistant"; Kannala & Brandt, PAMI 2006, eq. 6):
//      θ = atan2(r, Z), r = √(X² + Y²),  θ_d = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸),
//      uv = [fx θ_d X / r + cx, fy θ_d Y / r + cy]   (θ_d / r → 1 / Z at r = 0).
// 3. DoubleSphere k = [fx, fy, cx, cy, ξ, α] (Usenko, Demmel & Cremers, 3DV 2018,
//    eqs. 40–45):  d1 = ‖p‖,  d2 = √(X² + Y² + (ξ d1 + Z)²),
//      uv = [fx X, fy Y] / (α d2 + (1 − α)(ξ d1 + Z)) + [cx, cy];
//    ξ = α = 0 is the pinhole model.
// Units: f, c in pixels, the other coefficients dimensionless. Points behind
// the camera still give a value (no branch), so Jacobians stay smooth;
// initialise with the board in front.
#pragma once

#include <string>
#include <utility>

#include "boxplus/manifolds/se3.h"

namespace boxplus {

namespace camera {

[[noreturn]] void ThrowUnknownCameraModel(const std::string& name);

// Fixed-point steps of the Brown–Conrady models' Unproject (20 leave less than
// 1e-7 px out to 34° on the lenses the tests calibrate), Newton steps of
// Kannala–Brandt's θ.
constexpr int kUnprojectSteps = 20;
constexpr int kUnprojectNewtonSteps = 10;

// kFocals: 1 (f) or 2 (fx, fy); kRadial: number of radial coefficients
// k1, k2, k3; kTangential: p1, p2 (stored between k2 and k3, OpenCV's order);
// kRational: the denominator's k4, k5, k6 (after k3, OpenCV's order; needs
// kRadial = 3 and kTangential).
template <int kFocals, int kRadial, bool kTangential, bool kRational = false>
struct CameraModel {
  static_assert(!kRational || (kRadial == 3 && kTangential), "rational needs k1..k3, p1, p2");
  static constexpr int kSize = kFocals + 2 + kRadial + (kTangential ? 2 : 0) + (kRational ? 3 : 0);

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
      T rad = T(1.0) + poly;
      if constexpr (kRational) {
        const T* d = k + kFocals + 7;  // k4, k5, k6
        rad /= T(1.0) + r2 * (d[0] + r2 * (d[1] + r2 * d[2]));
      }
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

  template <typename T>
  static void ProjectPoint(const T* k, const T* p, T* uv) {
    Project(k, p[0] / p[2], p[1] / p[2], uv);
  }

  // A ray [x, y, 1] with Project(k, x, y) = uv: the affine part inverted exactly, the
  // distortion by kUnprojectSteps fixed-point steps x ← x − (D(x) − x_d), a
  // contraction where |dD/dx − I| < 1 (moderate distortion, as calibrated lenses have).
  template <typename T>
  static void Unproject(const T* k, const double* uv, T* ray) {
    const T& fx = k[0];
    const T& fy = k[kFocals - 1];
    const T xd = (T(uv[0]) - k[kFocals]) / fx;
    const T yd = (T(uv[1]) - k[kFocals + 1]) / fy;
    T x = xd, y = yd;
    if constexpr (kRadial > 0) {
      for (int i = 0; i < kUnprojectSteps; ++i) {
        T p[2];
        Project(k, x, y, p);
        x = x - ((p[0] - k[kFocals]) / fx - xd);
        y = y - ((p[1] - k[kFocals + 1]) / fy - yd);
      }
    }
    ray[0] = x;
    ray[1] = y;
    ray[2] = T(1.0);
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

struct Rational : CameraModel<2, 3, true, true> {
  static constexpr const char* kName = "rational";
};

struct KannalaBrandt {
  static constexpr const char* kName = "kannala_brandt";
  static constexpr int kSize = 8;

  template <typename T>
  static void ProjectPoint(const T* k, const T* p, T* uv) {
    const T r2 = p[0] * p[0] + p[1] * p[1];
    T scale;  // θ_d / r
    // At r = 0, atan2 and the division are 0/0; the limit θ_d / r = 1 / Z
    // (and its derivative, as θ_d / r = (1 + O(θ²)) / Z) hold there.
    if (r2 < T(1e-30)) {
      scale = T(1.0) / p[2];
    } else {
      const T r = sqrt(r2);
      const T theta = atan2(r, p[2]);
      const T t2 = theta * theta;
      const T poly = T(1.0) + t2 * (k[4] + t2 * (k[5] + t2 * (k[6] + t2 * k[7])));
      scale = theta * poly / r;
    }
    uv[0] = k[0] * scale * p[0] + k[2];
    uv[1] = k[1] * scale * p[1] + k[3];
  }

  // A ray [sin θ m/|m|, cos θ] with ProjectPoint(k, ray) = uv, m the normalised
  // pixel: θ from θ_d = |m| = θ(1 + k1 θ² + …) by Newton steps from θ = θ_d.
  template <typename T>
  static void Unproject(const T* k, const double* uv, T* ray) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T mx = (T(uv[0]) - k[2]) / k[0];
    const T my = (T(uv[1]) - k[3]) / k[1];
    const T theta_d = sqrt(mx * mx + my * my);
    if (theta_d < T(1e-15)) {
      ray[0] = mx;
      ray[1] = my;
      ray[2] = T(1.0);
      return;
    }
    T theta = theta_d;
    for (int i = 0; i < kUnprojectNewtonSteps; ++i) {
      const T t2 = theta * theta;
      const T f = theta * (T(1.0) + t2 * (k[4] + t2 * (k[5] + t2 * (k[6] + t2 * k[7])))) - theta_d;
      const T df = T(1.0) + t2 * (T(3.0) * k[4] +
                                  t2 * (T(5.0) * k[5] + t2 * (T(7.0) * k[6] + T(9.0) * t2 * k[7])));
      theta = theta - f / df;
    }
    const T s = sin(theta) / theta_d;
    ray[0] = s * mx;
    ray[1] = s * my;
    ray[2] = cos(theta);
  }
};

struct DoubleSphere {
  static constexpr const char* kName = "double_sphere";
  static constexpr int kSize = 6;

  template <typename T>
  static void ProjectPoint(const T* k, const T* p, T* uv) {
    const T& xi = k[4];
    const T& alpha = k[5];
    const T d1 = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    const T zs = xi * d1 + p[2];
    const T d2 = sqrt(p[0] * p[0] + p[1] * p[1] + zs * zs);
    const T den = alpha * d2 + (T(1.0) - alpha) * zs;
    uv[0] = k[0] * p[0] / den + k[2];
    uv[1] = k[1] * p[1] / den + k[3];
  }

  // The closed-form inverse (Usenko et al., eqs. 47–51): a unit ray with
  // ProjectPoint(k, ray) = uv, for pixels inside the model's valid image.
  template <typename T>
  static void Unproject(const T* k, const double* uv, T* ray) {
    using std::sqrt;
    const T& xi = k[4];
    const T& alpha = k[5];
    const T mx = (T(uv[0]) - k[2]) / k[0];
    const T my = (T(uv[1]) - k[3]) / k[1];
    const T r2 = mx * mx + my * my;
    const T mz = (T(1.0) - alpha * alpha * r2) /
                 (alpha * sqrt(T(1.0) - (T(2.0) * alpha - T(1.0)) * r2) + T(1.0) - alpha);
    const T scale = (mz * xi + sqrt(mz * mz + (T(1.0) - xi * xi) * r2)) / (mz * mz + r2);
    ray[0] = scale * mx;
    ray[1] = scale * my;
    ray[2] = scale * mz - xi;
  }
};

// Every model, in one list. A model's position in it is its number where a term
// stores the model as an int (the joint terms: a runtime switch inside autodiff);
// everything else names it.
inline constexpr const char* kCameraModelNames[] = {
    SimpleRadial::kName, Pinhole::kName,  Radial1::kName,       Radial2::kName,
    OpenCV5::kName,      Rational::kName, KannalaBrandt::kName, DoubleSphere::kName};

// The number of a model in kCameraModelNames; throws boxplus::Error for other names.
int CameraModelIndex(const std::string& name);

// f(Model{}) for the model with number `index` in kCameraModelNames.
template <class F>
auto WithCameraModelIndex(int index, F&& f) {
  switch (index) {
    case 0:
      return f(SimpleRadial{});
    case 1:
      return f(Pinhole{});
    case 2:
      return f(Radial1{});
    case 3:
      return f(Radial2{});
    case 4:
      return f(OpenCV5{});
    case 5:
      return f(Rational{});
    case 6:
      return f(KannalaBrandt{});
    case 7:
      return f(DoubleSphere{});
    default:  // a number no model has: refused, never taken for another model
      ThrowUnknownCameraModel("number " + std::to_string(index));
      return f(DoubleSphere{});  // not reached
  }
}

// f(Model{}) for the model named `name` ("simple_radial", "pinhole",
// "radial1", "radial2", "opencv5", "rational", "kannala_brandt",
// "double_sphere"); throws boxplus::Error for other names.
template <class F>
auto WithCameraModel(const std::string& name, F&& f) {
  return WithCameraModelIndex(CameraModelIndex(name), std::forward<F>(f));
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
