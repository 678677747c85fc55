// Pinhole projection of a known 3D point, with lens distortion.
//
// Residual (2):  r = W (π(k, p_in_cam) − z),  W = L⁻¹ with LLᵀ = Σ (pixels)
//   p_in_cam = x2cam.fromlocal(x2world.tolocal(p_in_world))
// i.e. world → x (by the inverse of x2world) → cam (by x2cam): the chain of the
// MTKM paper's project_point, so one factor serves mono (x2cam fixed to the
// identity), stereo (x2cam = left→right) and hand-eye problems.
// Parameter blocks: intrinsics k (ambient = the model's layout below),
// x2world (SE3, 7), x2cam (SE3, 7). Poses: [p, q(x,y,z,w)], local → parent.
//
// Camera models (normalised coordinates x = X/Z, y = Y/Z, r² = x² + y²):
//   SimpleRadial  k = [f, cx, cy, k1]          u = f·x·(1+k1 r²) + cx  (MTKM Listing 1)
//   Pinhole       k = [fx, fy, cx, cy]
//   Radial1       k = [fx, fy, cx, cy, k1]     radial 1 + k1 r²  (OpenCV: FIX_K2|FIX_K3|ZERO_TANGENT_DIST)
//   Radial2       k = [fx, fy, cx, cy, k1, k2] radial 1 + k1 r² + k2 r⁴ (OpenCV: FIX_K3|ZERO_TANGENT_DIST)
//   OpenCV5       k = [fx, fy, cx, cy, k1, k2, p1, p2, k3]  (OpenCV's default model:
//                 x' = x·rad + 2p1·xy + p2(r²+2x²), y' = y·rad + p1(r²+2y²) + 2p2·xy,
//                 rad = 1 + k1 r² + k2 r⁴ + k3 r⁶)
// Points behind the camera still give a residual (no branch), so Jacobians
// stay smooth; initialise with the board in front.
#pragma once

#include <memory>
#include <string>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/manifolds/se3.h"

namespace boxplus {

namespace camera {

[[noreturn]] void ThrowUnknownCameraModel(const std::string& name);

template <typename T>
void Distort(const T& x, const T& y, const T& k1, const T& k2, const T& p1, const T& p2,
             const T& k3, T* xd, T* yd) {
  const T r2 = x * x + y * y;
  const T rad = T(1.0) + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * rad + T(2.0) * p1 * x * y + p2 * (r2 + T(2.0) * x * x);
  *yd = y * rad + p1 * (r2 + T(2.0) * y * y) + T(2.0) * p2 * x * y;
}

struct SimpleRadial {
  static constexpr int kSize = 4;
  static constexpr const char* kName = "simple_radial";
  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    const T rad = T(1.0) + k[3] * (x * x + y * y);
    uv[0] = k[0] * x * rad + k[1];
    uv[1] = k[0] * y * rad + k[2];
  }
};

struct Pinhole {
  static constexpr int kSize = 4;
  static constexpr const char* kName = "pinhole";
  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    uv[0] = k[0] * x + k[2];
    uv[1] = k[1] * y + k[3];
  }
};

struct Radial1 {
  static constexpr int kSize = 5;
  static constexpr const char* kName = "radial1";
  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    const T rad = T(1.0) + k[4] * (x * x + y * y);
    uv[0] = k[0] * x * rad + k[2];
    uv[1] = k[1] * y * rad + k[3];
  }
};

struct Radial2 {
  static constexpr int kSize = 6;
  static constexpr const char* kName = "radial2";
  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    const T r2 = x * x + y * y;
    const T rad = T(1.0) + r2 * (k[4] + r2 * k[5]);
    uv[0] = k[0] * x * rad + k[2];
    uv[1] = k[1] * y * rad + k[3];
  }
};

struct OpenCV5 {
  static constexpr int kSize = 9;
  static constexpr const char* kName = "opencv5";
  template <typename T>
  static void Project(const T* k, const T& x, const T& y, T* uv) {
    T xd, yd;
    Distort(x, y, k[4], k[5], k[6], k[7], k[8], &xd, &yd);
    uv[0] = k[0] * xd + k[2];
    uv[1] = k[1] * yd + k[3];
  }
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

// p_in_cam = x2cam.fromlocal(x2world.tolocal(p_in_world)): the chain of every
// camera factor (poses [p, q(x,y,z,w)], local → parent).
template <typename T>
void ChainToCam(const T* x2world, const T* x2cam, const T* p_in_world, T* p_in_cam) {
  T d[3] = {p_in_world[0] - x2world[0], p_in_world[1] - x2world[1], p_in_world[2] - x2world[2]};
  T qinv[4], p_in_x[3];
  QuatConjugate(x2world + 3, qinv);
  QuatRotatePoint(qinv, d, p_in_x);
  QuatRotatePoint(x2cam + 3, p_in_x, p_in_cam);
  for (int i = 0; i < 3; ++i) p_in_cam[i] += x2cam[i];
}

// r = W (π(k, p_in_cam) − z) for one point (2 residuals).
template <class Model, typename T>
void ProjectionResidual(const T* k, const T* p_in_cam, const double* z, const Eigen::Matrix2d& W,
                        T* residual) {
  T uv[2];
  Model::Project(k, p_in_cam[0] / p_in_cam[2], p_in_cam[1] / p_in_cam[2], uv);
  const T e0 = uv[0] - T(z[0]), e1 = uv[1] - T(z[1]);
  residual[0] = T(W(0, 0)) * e0 + T(W(0, 1)) * e1;
  residual[1] = T(W(1, 0)) * e0 + T(W(1, 1)) * e1;
}

}  // namespace camera

template <class Model>
class PinholePointFunctor {
 public:
  PinholePointFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
                      const Eigen::Vector3d& p_in_world)
      : z_(z), W_(sqrt_info), p_(p_in_world) {}

  template <typename T>
  bool operator()(const T* k, const T* x2world, const T* x2cam, T* residual) const {
    const T p[3] = {T(p_[0]), T(p_[1]), T(p_[2])};
    T p_in_cam[3];
    camera::ChainToCam(x2world, x2cam, p, p_in_cam);
    camera::ProjectionResidual<Model>(k, p_in_cam, z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Eigen::Vector2d& z,
                                                     const Eigen::Matrix2d& sqrt_info,
                                                     const Eigen::Vector3d& p_in_world) {
    return std::make_shared<ceres::AutoDiffCostFunction<PinholePointFunctor, 2, Model::kSize, 7, 7>>(
        new PinholePointFunctor(z, sqrt_info, p_in_world));
  }

 private:
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::Vector3d p_;
};

// The factor for a camera model chosen at run time by name ("simple_radial",
// "pinhole", "radial1", "radial2", "opencv5"); throws boxplus::Error for other names.
std::shared_ptr<ceres::CostFunction> MakePinholePointFactor(const std::string& model,
                                                            const Eigen::Vector2d& z,
                                                            const Eigen::Matrix2d& sqrt_info,
                                                            const Eigen::Vector3d& p_in_world);
// Number of intrinsic parameters of a camera model.
int CameraModelSize(const std::string& model);

}  // namespace boxplus
