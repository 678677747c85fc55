#include "boxplus/factors/imu/spline_terms.h"

#include <cmath>
#include <utility>

#include <ceres/autodiff_cost_function.h>

#include "boxplus/errors.h"
#include "boxplus/factors/camera/models.h"
#include "boxplus/factors/imu/se3_spline.h"
#include "boxplus/manifolds/rotation_math.h"

namespace boxplus {
namespace {

constexpr int kKnot = 7;  // a control point: SE3 [p, q]

// One IMU sample: where it falls on its segment, the reading and its W.
struct ImuSample {
  double u, dt;
  Eigen::Vector3d z;
  Eigen::Matrix3d W;

  // The spline's quantities at the sample (any pointer may be null).
  template <typename T>
  void Evaluate(const T* k0, const T* k1, const T* k2, const T* k3, T* q, T* a, T* omega) const {
    EvaluateAt(T(u), k0, k1, k2, k3, q, a, omega);
  }

  template <typename T>
  void EvaluateAt(const T& at, const T* k0, const T* k1, const T* k2, const T* k3, T* q, T* a,
                  T* omega, T* alpha = nullptr) const {
    const T* knots[4] = {k0, k1, k2, k3};
    spline::Evaluate(knots, at, dt, static_cast<T*>(nullptr), q, static_cast<T*>(nullptr), a, omega,
                     alpha);
  }

  // u of the sample when its IMU's clock is off the body's by d (the sample's body time is
  // its own + d), u having been computed with the offset d0.
  template <typename T>
  T Shifted(const T* d, double d0) const {
    return T(u) + (d[0] - T(d0)) / T(dt);
  }

  // The specific force in the body frame, Rᵀ (a − |g| ĝ), from the pose's quaternion q
  // and the world acceleration a.
  template <typename T>
  static void SpecificForce(const T* q, const T* a, const T* gravity_dir, double g, T* f) {
    T f_world[3], q_inv[4];
    for (int i = 0; i < 3; ++i) f_world[i] = a[i] - T(g) * gravity_dir[i];
    QuatConjugate(q, q_inv);
    QuatRotatePoint(q_inv, f_world, f);
  }

  // r = W (predicted + bias − z)
  template <typename T>
  void Residual(const T* predicted, const T* bias, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = predicted[i] + bias[i] - T(z[i]);
    WhitenInPlace<3>(W, r);
  }
};

template <typename T>
void Cross(const T* x, const T* y, T* out) {
  out[0] = x[1] * y[2] - x[2] * y[1];
  out[1] = x[2] * y[0] - x[0] * y[2];
  out[2] = x[0] * y[1] - x[1] * y[0];
}

// The acceleration of a point at `arm` from the body's origin beyond the origin's own:
// the tangential α × r and the centripetal ω × (ω × r) (body frame).
template <typename T>
void LeverArmAcceleration(const T* omega, const T* alpha, const T* arm, T* out) {
  T wxr[3], centripetal[3], tangential[3];
  Cross(omega, arm, wxr);
  Cross(omega, wxr, centripetal);
  Cross(alpha, arm, tangential);
  for (int i = 0; i < 3; ++i) out[i] = tangential[i] + centripetal[i];
}

// The IMU's own scale and misalignment (Kalibr's "scale-misalignment" model), a
// 6-vector [s_x, s_y, s_z, m_yx, m_zx, m_zy] read as the lower-triangular matrix
//   M = [[s_x, 0, 0], [m_yx, s_y, 0], [m_zx, m_zy, s_z]],
// the reading M x + b of the true x: triangular, since a full M would trade its
// rotation part with imu_from_cam's.
template <typename T>
void ApplyIntrinsics(const T* m, const T* x, T* out) {
  out[0] = m[0] * x[0];
  out[1] = m[3] * x[0] + m[1] * x[1];
  out[2] = m[4] * x[0] + m[5] * x[1] + m[2] * x[2];
}

// r = W (M x + b − z): the residual of a sensor reading x through its scale and
// misalignment m (ApplyIntrinsics), or x itself when m is null.
template <typename T>
void ReadingResidual(const ImuSample& s, const T* m, const T* x, const T* bias, T* r) {
  if (m == nullptr) {
    s.Residual(x, bias, r);
    return;
  }
  T read[3];
  ApplyIntrinsics(m, x, read);
  s.Residual(read, bias, r);
}

class GyroFunctor {
 public:
  explicit GyroFunctor(ImuSample s) : s_(std::move(s)) {}

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* bias, T* r) const {
    T omega[3];
    s_.Evaluate(k0, k1, k2, k3, static_cast<T*>(nullptr), static_cast<T*>(nullptr), omega);
    s_.Residual(omega, bias, r);
    return true;
  }

  // with the gyroscope's scale and misalignment M (ApplyIntrinsics)
  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* bias, const T* m,
                  T* r) const {
    T omega[3];
    s_.Evaluate(k0, k1, k2, k3, static_cast<T*>(nullptr), static_cast<T*>(nullptr), omega);
    ReadingResidual(s_, m, omega, bias, r);
    return true;
  }

 private:
  ImuSample s_;
};

class AccelFunctor {
 public:
  AccelFunctor(ImuSample s, double g) : s_(std::move(s)), g_(g) {}

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* bias,
                  const T* gravity_dir, T* r) const {
    T f[3];
    Force(k0, k1, k2, k3, gravity_dir, f);
    s_.Residual(f, bias, r);
    return true;
  }

  // with the accelerometer's scale and misalignment M (ApplyIntrinsics)
  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* bias,
                  const T* gravity_dir, const T* m, T* r) const {
    T f[3];
    Force(k0, k1, k2, k3, gravity_dir, f);
    ReadingResidual(s_, m, f, bias, r);
    return true;
  }

  // and the size effect: the y and z sensing elements sit at r_y, r_z (the block [r_y,
  // r_z], m) from the x element, the IMU's origin, so each feels its own point's
  // acceleration: f_i = e_iᵀ (f + α × r_i + ω × (ω × r_i)) (Kalibr's
  // scale-misalignment-size-effect model)
  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* bias,
                  const T* gravity_dir, const T* m, const T* size, T* r) const {
    const T* knots[4] = {k0, k1, k2, k3};
    T q[4], a[3], omega[3], alpha[3], f[3];
    spline::Evaluate(knots, T(s_.u), s_.dt, static_cast<T*>(nullptr), q, static_cast<T*>(nullptr),
                     a, omega, alpha);
    ImuSample::SpecificForce(q, a, gravity_dir, g_, f);
    for (int axis = 1; axis < 3; ++axis) {
      T extra[3];
      LeverArmAcceleration(omega, alpha, size + 3 * (axis - 1), extra);
      f[axis] += extra[axis];
    }
    ReadingResidual(s_, m, f, bias, r);
    return true;
  }

 private:
  template <typename T>
  void Force(const T* k0, const T* k1, const T* k2, const T* k3, const T* gravity_dir, T* f) const {
    T q[4], a[3];
    s_.Evaluate(k0, k1, k2, k3, q, a, static_cast<T*>(nullptr));
    ImuSample::SpecificForce(q, a, gravity_dir, g_, f);
  }

  ImuSample s_;
  double g_;
};

// Another IMU on the rig, at body_from_imu = [r, q_k] (the body IMU's frame):
// it turns with the body and feels, besides the body's specific force, the
// tangential and centripetal acceleration of its lever arm r. Optional blocks after
// the fixed ones, in this order: kOffset, its time offset d (R¹; its samples are read
// at body time t + d); its own scale and misalignment M (R⁶, ApplyIntrinsics). Ceres
// calls the operator with as many blocks as the cost function has, so the arity picks
// the overload, and kOffset says whether a lone extra block is d or M.
template <bool kOffset>
class OffsetGyroFunctor {
 public:
  OffsetGyroFunctor(ImuSample s, double d0) : s_(std::move(s)), d0_(d0) {}

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, T* r) const {
    return Residual(T(s_.u), k0, k1, k2, k3, body_from_imu, bias, static_cast<const T*>(nullptr),
                    r);
  }

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, const T* extra, T* r) const {
    if constexpr (kOffset) {
      return Residual(s_.Shifted(extra, d0_), k0, k1, k2, k3, body_from_imu, bias,
                      static_cast<const T*>(nullptr), r);
    } else {
      return Residual(T(s_.u), k0, k1, k2, k3, body_from_imu, bias, extra, r);
    }
  }

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, const T* d, const T* m, T* r) const {
    return Residual(s_.Shifted(d, d0_), k0, k1, k2, k3, body_from_imu, bias, m, r);
  }

 private:
  template <typename T>
  bool Residual(const T& u, const T* k0, const T* k1, const T* k2, const T* k3,
                const T* body_from_imu, const T* bias, const T* m, T* r) const {
    T omega[3], q_inv[4], omega_k[3];
    s_.EvaluateAt(u, k0, k1, k2, k3, static_cast<T*>(nullptr), static_cast<T*>(nullptr), omega);
    QuatConjugate(body_from_imu + 3, q_inv);
    QuatRotatePoint(q_inv, omega, omega_k);
    ReadingResidual(s_, m, omega_k, bias, r);
    return true;
  }

  ImuSample s_;
  double d0_;
};

template <bool kOffset>
class OffsetAccelFunctor {
 public:
  OffsetAccelFunctor(ImuSample s, double g, double d0) : s_(std::move(s)), g_(g), d0_(d0) {}

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, const T* gravity_dir, T* r) const {
    return Residual(T(s_.u), k0, k1, k2, k3, body_from_imu, bias, gravity_dir,
                    static_cast<const T*>(nullptr), r);
  }

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, const T* gravity_dir, const T* extra, T* r) const {
    if constexpr (kOffset) {
      return Residual(s_.Shifted(extra, d0_), k0, k1, k2, k3, body_from_imu, bias, gravity_dir,
                      static_cast<const T*>(nullptr), r);
    } else {
      return Residual(T(s_.u), k0, k1, k2, k3, body_from_imu, bias, gravity_dir, extra, r);
    }
  }

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* body_from_imu,
                  const T* bias, const T* gravity_dir, const T* d, const T* m, T* r) const {
    return Residual(s_.Shifted(d, d0_), k0, k1, k2, k3, body_from_imu, bias, gravity_dir, m, r);
  }

 private:
  template <typename T>
  bool Residual(const T& u, const T* k0, const T* k1, const T* k2, const T* k3,
                const T* body_from_imu, const T* bias, const T* gravity_dir, const T* m,
                T* r) const {
    T q[4], a[3], omega[3], alpha[3];
    s_.EvaluateAt(u, k0, k1, k2, k3, q, a, omega, alpha);
    T f[3];
    ImuSample::SpecificForce(q, a, gravity_dir, g_, f);
    T extra[3];
    LeverArmAcceleration(omega, alpha, body_from_imu, extra);  // the arm r: the pose's position
    for (int i = 0; i < 3; ++i) f[i] += extra[i];
    T qk_inv[4], f_k[3];
    QuatConjugate(body_from_imu + 3, qk_inv);
    QuatRotatePoint(qk_inv, f, f_k);
    ReadingResidual(s_, m, f_k, bias, r);
    return true;
  }

  ImuSample s_;
  double g_;
  double d0_;
};

// The cost function of an other-IMU functor F<kOffset> whose fixed blocks are
// kFixed...: the optional blocks (d, M) appended in the functors' order.
template <template <bool> class F, int... kFixed, typename... Args>
std::shared_ptr<ceres::CostFunction> OtherImuCost(bool time_offset, bool intrinsics,
                                                  Args&&... args) {
  if (time_offset && intrinsics) {
    return std::make_shared<ceres::AutoDiffCostFunction<F<true>, 3, kFixed..., 1, 6>>(
        new F<true>(std::forward<Args>(args)...));
  }
  if (time_offset) {
    return std::make_shared<ceres::AutoDiffCostFunction<F<true>, 3, kFixed..., 1>>(
        new F<true>(std::forward<Args>(args)...));
  }
  if (intrinsics) {
    return std::make_shared<ceres::AutoDiffCostFunction<F<false>, 3, kFixed..., 6>>(
        new F<false>(std::forward<Args>(args)...));
  }
  return std::make_shared<ceres::AutoDiffCostFunction<F<false>, 3, kFixed...>>(
      new F<false>(std::forward<Args>(args)...));
}

// kRolling: one more block, the line delay ℓ (s per image row): the corner's row v
// (its measured one) was read out ℓ·v after the frame's timestamp.
template <class Model, bool kRolling>
class ReprojectionFunctor {
 public:
  ReprojectionFunctor(double t_rel, double dt, const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
                      const Eigen::Vector3d& p)
      : t_rel_(t_rel), dt_(dt), z_(z), W_(W), p_(p) {}

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* imu_from_cam,
                  const T* offset, const T* intrinsics, T* r) const {
    return Residual(k0, k1, k2, k3, imu_from_cam, T(t_rel_) + offset[0], intrinsics, r);
  }

  template <typename T>
  bool operator()(const T* k0, const T* k1, const T* k2, const T* k3, const T* imu_from_cam,
                  const T* offset, const T* intrinsics, const T* line_delay, T* r) const {
    return Residual(k0, k1, k2, k3, imu_from_cam, T(t_rel_) + offset[0] + line_delay[0] * T(z_[1]),
                    intrinsics, r);
  }

 private:
  // t: the corner's IMU time after the segment's start
  template <typename T>
  bool Residual(const T* k0, const T* k1, const T* k2, const T* k3, const T* imu_from_cam,
                const T& t, const T* intrinsics, T* r) const {
    const T* knots[4] = {k0, k1, k2, k3};
    const T u = t / T(dt_);
    T p_wi[3], q_wi[4];
    spline::Evaluate(knots, u, dt_, p_wi, q_wi, static_cast<T*>(nullptr), static_cast<T*>(nullptr),
                     static_cast<T*>(nullptr));
    // p_in_imu = q_wiᵀ (p_w − p_wi); p_in_cam = q_icᵀ (p_in_imu − p_ic)
    T d[3], q_inv[4], p_imu[3], e[3], q_ic_inv[4], p_cam[3];
    for (int i = 0; i < 3; ++i) d[i] = T(p_[i]) - p_wi[i];
    QuatConjugate(q_wi, q_inv);
    QuatRotatePoint(q_inv, d, p_imu);
    for (int i = 0; i < 3; ++i) e[i] = p_imu[i] - imu_from_cam[i];
    QuatConjugate(imu_from_cam + 3, q_ic_inv);
    QuatRotatePoint(q_ic_inv, e, p_cam);
    T uv[2];
    Model::ProjectPoint(intrinsics, p_cam, uv);
    r[0] = uv[0] - T(z_[0]);
    r[1] = uv[1] - T(z_[1]);
    WhitenInPlace<2>(W_, r);
    return true;
  }

  double t_rel_, dt_;
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::Vector3d p_;
};

void CheckTime(double u, double dt, const char* what) {
  BOXPLUS_CHECK(std::isfinite(u) && std::isfinite(dt) && dt > 0, what,
                ": u and dt must be finite, dt > 0 (got u = ", u, ", dt = ", dt, ")");
}

}  // namespace

std::shared_ptr<ceres::CostFunction> MakeSplineGyroFactor(double u, double dt,
                                                          const Eigen::Vector3d& z,
                                                          const NoiseModel& noise,
                                                          bool intrinsics) {
  CheckTime(u, dt, "spline gyro factor");
  BOXPLUS_CHECK(z.allFinite(), "spline gyro factor: non-finite reading");
  const Eigen::Matrix3d W = noise.Fixed<3>("spline gyro factor");
  auto* f = new GyroFunctor(ImuSample{u, dt, z, W});
  if (intrinsics) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<GyroFunctor, 3, kKnot, kKnot, kKnot, kKnot, 3, 6>>(f);
  }
  return std::make_shared<
      ceres::AutoDiffCostFunction<GyroFunctor, 3, kKnot, kKnot, kKnot, kKnot, 3>>(f);
}

std::shared_ptr<ceres::CostFunction> MakeSplineAccelFactor(double u, double dt,
                                                           const Eigen::Vector3d& z,
                                                           const NoiseModel& noise,
                                                           double gravity_magnitude,
                                                           bool intrinsics, bool size_effect) {
  CheckTime(u, dt, "spline accelerometer factor");
  BOXPLUS_CHECK(intrinsics || !size_effect,
                "spline accelerometer factor: the size effect comes with the intrinsics block");
  BOXPLUS_CHECK(z.allFinite() && std::isfinite(gravity_magnitude) && gravity_magnitude > 0,
                "spline accelerometer factor: non-finite reading or |g| <= 0");
  const Eigen::Matrix3d W = noise.Fixed<3>("spline accelerometer factor");
  auto* f = new AccelFunctor(ImuSample{u, dt, z, W}, gravity_magnitude);
  if (size_effect) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<AccelFunctor, 3, kKnot, kKnot, kKnot, kKnot, 3, 3, 6, 6>>(f);
  }
  if (intrinsics) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<AccelFunctor, 3, kKnot, kKnot, kKnot, kKnot, 3, 3, 6>>(f);
  }
  return std::make_shared<
      ceres::AutoDiffCostFunction<AccelFunctor, 3, kKnot, kKnot, kKnot, kKnot, 3, 3>>(f);
}

std::shared_ptr<ceres::CostFunction> MakeSplineOffsetGyroFactor(double u, double dt,
                                                                const Eigen::Vector3d& z,
                                                                const NoiseModel& noise,
                                                                bool time_offset, double d0,
                                                                bool intrinsics) {
  CheckTime(u, dt, "spline gyro factor of another IMU");
  BOXPLUS_CHECK(z.allFinite() && std::isfinite(d0),
                "spline gyro factor of another IMU: non-finite reading or offset");
  const Eigen::Matrix3d W = noise.Fixed<3>("spline gyro factor of another IMU");
  return OtherImuCost<OffsetGyroFunctor, kKnot, kKnot, kKnot, kKnot, kKnot, 3>(
      time_offset, intrinsics, ImuSample{u, dt, z, W}, d0);
}

std::shared_ptr<ceres::CostFunction> MakeSplineOffsetAccelFactor(
    double u, double dt, const Eigen::Vector3d& z, const NoiseModel& noise,
    double gravity_magnitude, bool time_offset, double d0, bool intrinsics) {
  CheckTime(u, dt, "spline accelerometer factor of another IMU");
  BOXPLUS_CHECK(z.allFinite() && std::isfinite(gravity_magnitude) && gravity_magnitude > 0 &&
                    std::isfinite(d0),
                "spline accelerometer factor of another IMU: non-finite reading or offset, or "
                "|g| <= 0");
  const Eigen::Matrix3d W = noise.Fixed<3>("spline accelerometer factor of another IMU");
  return OtherImuCost<OffsetAccelFunctor, kKnot, kKnot, kKnot, kKnot, kKnot, 3, 3>(
      time_offset, intrinsics, ImuSample{u, dt, z, W}, gravity_magnitude, d0);
}

std::shared_ptr<ceres::CostFunction> MakeSplineReprojectionFactor(
    const std::string& model, double t_rel, double dt, const Eigen::Vector2d& z,
    const NoiseModel& noise, const Eigen::Vector3d& p_in_world, bool rolling_shutter) {
  CheckTime(t_rel, dt, "spline reprojection factor");
  BOXPLUS_CHECK(z.allFinite() && p_in_world.allFinite(),
                "spline reprojection factor: non-finite pixel or target point");
  const Eigen::Matrix2d W = noise.Fixed<2>("spline reprojection factor");
  return camera::WithCameraModel(model, [&](auto m) -> std::shared_ptr<ceres::CostFunction> {
    using Model = decltype(m);
    if (rolling_shutter) {
      using F = ReprojectionFunctor<Model, true>;
      return std::make_shared<
          ceres::AutoDiffCostFunction<F, 2, kKnot, kKnot, kKnot, kKnot, kKnot, 1, Model::kSize, 1>>(
          new F(t_rel, dt, z, W, p_in_world));
    }
    using F = ReprojectionFunctor<Model, false>;
    return std::make_shared<
        ceres::AutoDiffCostFunction<F, 2, kKnot, kKnot, kKnot, kKnot, kKnot, 1, Model::kSize>>(
        new F(t_rel, dt, z, W, p_in_world));
  });
}

}  // namespace boxplus
