// The terms of joint calibration of 3D systems (Le & Ng, "Joint calibration of
// multiple sensors", IROS 2009) as one autodiff factor family.
//
// A *3D system* s turns a datum u into a point p_in_s = I_s(α_s, u) in its own
// frame (eq. 3); root_from_s (SE3) places it in the frame of the root system
// (identity for the root). A term combines one or two such points with a
// plane, a line or a camera. The point operands (PointSpec):
//   kConstant  p = c                          (a range finder, eq. 12; known targets)
//   kVariable  p = X, an R³ block              (a stereo point triangulated by the solver)
//   kChain     p = base_from_target(dh, q + e, mount) · c      (robot arm, eq. 11)
//              base_from_target = base_from_chain · A₁(q₁+e₁) … Aₙ(qₙ+eₙ) · end_from_target
//              with Aⱼ standard or modified DH (kinematics/dh.h); the entries of the n×4
//              table [θ offset, d, a, α] listed in `unknown` come from the dh block (Rᵐ),
//              the others are the nominal constants; e (Rⁿ, optional) are encoder
//              errors of this reading, end_from_target the mount (SE3 block or constant).
//   kSheet     p = s·x̂, x̂ = ray(k, uv) = [x, y, 1], s = d / (n·x̂)  (light-sheet triangulation)
//              with the sheet {p : n·p = d} a Plane block [n (unit), d] in the camera frame.
//   kBeam      the same with the sheet of a projector at angle β (eq. 10): in the
//              laser's frame n_L(β) = (cos β, 0, −sin β), d_L = 0, so n = R n_L(β),
//              d = n·t with cam_from_laser = [t, R] an SE3 block.
// The residuals (e the error, r = W e with WᵀW = Σ⁻¹ of the term's NoiseModel):
//   kLink       e = P_a − P_b (3)                        (extrinsic term, eq. 4)
//   kDistance   e = ‖p_a − p_b‖ − d̄ (1)                  (distance preservation, eq. 5)
//   kPlane      e = n·P_a − d (1), the plane in the root frame   (coplanarity, eq. 6)
//   kLine       e = (I − v vᵀ)(P_a − c) (3)              (collinearity, eq. 6)
//   kLineAnchor e = v·c (1) in the line's own frame: fixes the slide of c along v
//   kProjection e = π(k, cam_from_system · root_from_system⁻¹ · P_a) − z (2, pixels)
//   kTargetProjection  the same for M points c_j of one chain target at one reading
//               (a board view in one camera): 2M residuals, each pair whitened by the
//               2 × 2 W, base_from_target evaluated once (M times cheaper than M terms)
// with P = root_from_s · p. A plane (SurfaceSpec) is a Plane block [n, d] or a Line
// block [v (unit), c] expressed in the frame of its owner system (pose block) or in
// the root frame (no pose), or the plane z = 0 of a chain's target
// (n = R e_z, d = n·t of base_from_target) — the board plane as the arm sees it.
// Poses [p, q(x,y,z,w)], tangent [δp, δθ]; lengths in metres, angles in radians,
// pixels for z of kProjection. Every camera model of camera/models.h, held by its
// number in camera::kCameraModelNames; a pixel's ray is the model's Unproject.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ceres/dynamic_autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/camera/models.h"
#include "boxplus/factors/kinematics/dh.h"
#include "boxplus/noise.h"

namespace boxplus {

namespace joint {

using Pose7 = Eigen::Matrix<double, 7, 1>;
constexpr int kNoBlock = -1;
constexpr int kMaxJoints = 16;

struct ChainSpec {
  kinematics::DHConvention convention = kinematics::DHConvention::kStandard;
  Eigen::MatrixXd nominal;   // n × 4 [θ offset, d, a, α]
  std::vector<int> unknown;  // entries 4·row + column taken from the dh block, in its order
  Eigen::VectorXd joints;    // the readings q (rad)
  int dh = kNoBlock;         // Rᵐ, m = unknown.size()
  int encoder = kNoBlock;    // Rⁿ errors e of these readings
  int mount = kNoBlock;      // SE3 end_from_target; else mount_value
  Pose7 base_from_chain = (Pose7() << 0, 0, 0, 0, 0, 0, 1).finished();
  Pose7 mount_value = (Pose7() << 0, 0, 0, 0, 0, 0, 1).finished();
};

enum class PointKind { kConstant = 0, kVariable, kChain, kSheet, kBeam };

struct PointSpec {
  PointKind kind = PointKind::kConstant;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();  // kConstant: p; kChain: p_in_target
  int block = kNoBlock;                         // kVariable: R³
  ChainSpec chain;                              // kChain
  int model = 0;                                // kSheet, kBeam: camera model index
  int camera = kNoBlock;                        // intrinsics block
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double beta = 0.0;
  int sheet = kNoBlock;  // kSheet: Plane [n, d]; kBeam: SE3 cam_from_laser
  int pose = kNoBlock;   // root_from_system (none: the root)
};

enum class SurfaceKind { kPlane = 0, kLine, kChainPlane };

struct SurfaceSpec {
  SurfaceKind kind = SurfaceKind::kPlane;
  int block = kNoBlock;  // kPlane: [n, d]; kLine: [v, c]
  ChainSpec chain;       // kChainPlane
  int pose = kNoBlock;   // root_from_owner (none: the root frame)
};

struct CameraSpec {
  int model = 0;
  int intrinsics = kNoBlock;
  int cam_from_system = kNoBlock;  // SE3 (none: the system's frame is this camera's)
  int pose = kNoBlock;             // root_from_system
};

enum class TermKind {
  kLink = 0,
  kDistance,
  kPlane,
  kLine,
  kLineAnchor,
  kProjection,
  kTargetProjection
};

struct TermSpec {
  TermKind kind = TermKind::kLink;
  PointSpec a, b;
  SurfaceSpec surface;
  CameraSpec camera;
  Eigen::VectorXd z;  // kDistance: [d̄]; kProjection: [u, v]; kTargetProjection: [u₁, v₁, …]
  Eigen::MatrixXd W;  // noise dim × noise dim
  Eigen::MatrixXd targets;  // kTargetProjection: M × 3 points c_j in the target frame
};

// Dimension of the noise of a term kind (the residual size but for
// kTargetProjection, whose 2M residuals are whitened pair by pair).
int TermResidualSize(TermKind kind);

namespace internal {

// π(k, p) of a point in the camera frame, for the model numbered `model`.
template <typename T>
void Project(int model, const T* k, const T* p, T* uv) {
  camera::WithCameraModelIndex(model, [&](auto m) { decltype(m)::ProjectPoint(k, p, uv); });
}

// A ray through the pixel uv (any length), for the model numbered `model`.
template <typename T>
void Ray(int model, const T* k, const Eigen::Vector2d& uv, T* ray) {
  camera::WithCameraModelIndex(model, [&](auto m) { decltype(m)::Unproject(k, uv.data(), ray); });
}

template <typename T>
void Transform(const T* b_from_a, const T* p_in_a, T* p_in_b) {
  QuatRotatePoint(b_from_a + 3, p_in_a, p_in_b);
  for (int i = 0; i < 3; ++i) p_in_b[i] += b_from_a[i];
}

template <typename T>
void InverseTransform(const T* b_from_a, const T* p_in_b, T* p_in_a) {
  const T d[3] = {p_in_b[0] - b_from_a[0], p_in_b[1] - b_from_a[1], p_in_b[2] - b_from_a[2]};
  T q[4];
  QuatConjugate(b_from_a + 3, q);
  QuatRotatePoint(q, d, p_in_a);
}

// base_from_target of a chain at its reading.
template <typename T>
void ChainTargetPose(const ChainSpec& c, T const* const* x, T* base_from_target) {
  const int n = static_cast<int>(c.nominal.rows());  // ≤ kMaxJoints (MakeJointTerm checks)
  T table[4 * kMaxJoints], joints[kMaxJoints];
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < 4; ++i) table[4 * j + i] = T(c.nominal(j, i));
    joints[j] = T(c.joints[j]);
    if (c.encoder != kNoBlock) joints[j] += x[c.encoder][j];
  }
  for (size_t u = 0; u < c.unknown.size(); ++u) table[c.unknown[u]] = x[c.dh][u];
  T base[7], end[7], mount[7];
  for (int i = 0; i < 7; ++i) {
    base[i] = T(c.base_from_chain[i]);
    mount[i] = c.mount != kNoBlock ? x[c.mount][i] : T(c.mount_value[i]);
  }
  kinematics::DHChainPose(c.convention, n, table, joints, base, end);
  kinematics::Compose(end, mount, base_from_target);
}

// A sheet {n·p = d} in the camera frame met by the ray of the pixel.
template <typename T>
void SheetPoint(const PointSpec& s, const T* n, const T& d, T const* const* x, T* p) {
  T ray[3];
  Ray(s.model, x[s.camera], s.uv, ray);
  const T depth = d / (n[0] * ray[0] + n[1] * ray[1] + n[2] * ray[2]);
  for (int i = 0; i < 3; ++i) p[i] = depth * ray[i];
}

// p in the system's frame.
template <typename T>
void SystemPoint(const PointSpec& s, T const* const* x, T* p) {
  switch (s.kind) {
    case PointKind::kConstant:
      for (int i = 0; i < 3; ++i) p[i] = T(s.c[i]);
      return;
    case PointKind::kVariable:
      for (int i = 0; i < 3; ++i) p[i] = x[s.block][i];
      return;
    case PointKind::kChain: {
      T pose[7];
      ChainTargetPose(s.chain, x, pose);
      const T c[3] = {T(s.c[0]), T(s.c[1]), T(s.c[2])};
      Transform(pose, c, p);
      return;
    }
    case PointKind::kSheet: {
      const T* plane = x[s.sheet];
      SheetPoint(s, plane, plane[3], x, p);
      return;
    }
    case PointKind::kBeam: {
      using std::cos;
      using std::sin;
      const T* cam_from_laser = x[s.sheet];
      const T n_laser[3] = {T(cos(s.beta)), T(0.0), T(-sin(s.beta))};
      T n[3];
      QuatRotatePoint(cam_from_laser + 3, n_laser, n);
      const T d = n[0] * cam_from_laser[0] + n[1] * cam_from_laser[1] + n[2] * cam_from_laser[2];
      SheetPoint(s, n, d, x, p);
      return;
    }
  }
}

// P = root_from_system · p.
template <typename T>
void RootPoint(const PointSpec& s, T const* const* x, T* P) {
  T p[3];
  SystemPoint(s, x, p);
  if (s.pose == kNoBlock) {
    for (int i = 0; i < 3; ++i) P[i] = p[i];
  } else {
    Transform(x[s.pose], p, P);
  }
}

// A plane [n, d] or a line [v, c] of the surface in the root frame.
template <typename T>
void RootSurface(const SurfaceSpec& s, T const* const* x, T* out) {
  if (s.kind == SurfaceKind::kChainPlane) {
    T pose[7];
    ChainTargetPose(s.chain, x, pose);
    const T ez[3] = {T(0.0), T(0.0), T(1.0)};
    QuatRotatePoint(pose + 3, ez, out);
    out[3] = out[0] * pose[0] + out[1] * pose[1] + out[2] * pose[2];
  } else {
    const int m = s.kind == SurfaceKind::kPlane ? 4 : 6;
    for (int i = 0; i < m; ++i) out[i] = x[s.block][i];
  }
  if (s.pose == kNoBlock) return;
  const T* T_ = x[s.pose];
  T v[3];
  QuatRotatePoint(T_ + 3, out, v);
  if (s.kind == SurfaceKind::kLine) {
    T c[3];
    Transform(T_, out + 3, c);
    for (int i = 0; i < 3; ++i) out[3 + i] = c[i];
  } else {
    out[3] += v[0] * T_[0] + v[1] * T_[1] + v[2] * T_[2];
  }
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

// π(k, cam_from_system · root_from_system⁻¹ · P) − z, whitened by the 2 × 2 W.
template <typename T>
void ProjectionResidual(const CameraSpec& c, const T* P, const double* z, const Eigen::MatrixXd& W,
                        T const* const* x, T* r) {
  T p_sys[3], p_cam[3], e[2];
  if (c.pose == kNoBlock) {
    for (int i = 0; i < 3; ++i) p_sys[i] = P[i];
  } else {
    InverseTransform(x[c.pose], P, p_sys);
  }
  if (c.cam_from_system == kNoBlock) {
    for (int i = 0; i < 3; ++i) p_cam[i] = p_sys[i];
  } else {
    Transform(x[c.cam_from_system], p_sys, p_cam);
  }
  Project(c.model, x[c.intrinsics], p_cam, e);
  e[0] -= T(z[0]);
  e[1] -= T(z[1]);
  r[0] = W(0, 0) * e[0] + W(0, 1) * e[1];
  r[1] = W(1, 0) * e[0] + W(1, 1) * e[1];
}

}  // namespace internal

class JointTermFunctor {
 public:
  explicit JointTermFunctor(TermSpec spec) : s_(std::move(spec)) {}

  template <typename T>
  bool operator()(T const* const* x, T* r) const {
    if (s_.kind == TermKind::kTargetProjection) {
      T pose[7], p[3], P[3];
      internal::ChainTargetPose(s_.a.chain, x, pose);
      for (Eigen::Index j = 0; j < s_.targets.rows(); ++j) {
        const T c[3] = {T(s_.targets(j, 0)), T(s_.targets(j, 1)), T(s_.targets(j, 2))};
        internal::Transform(pose, c, p);
        if (s_.a.pose == kNoBlock) {
          for (int i = 0; i < 3; ++i) P[i] = p[i];
        } else {
          internal::Transform(x[s_.a.pose], p, P);
        }
        internal::ProjectionResidual(s_.camera, P, s_.z.data() + 2 * j, s_.W, x, r + 2 * j);
      }
      return true;
    }
    if (s_.kind == TermKind::kProjection) {
      T P[3];
      internal::RootPoint(s_.a, x, P);
      internal::ProjectionResidual(s_.camera, P, s_.z.data(), s_.W, x, r);
      return true;
    }
    const int m = TermResidualSize(s_.kind);
    T e[3];
    switch (s_.kind) {
      case TermKind::kLink: {
        T Pb[3];
        internal::RootPoint(s_.a, x, e);
        internal::RootPoint(s_.b, x, Pb);
        for (int i = 0; i < 3; ++i) e[i] -= Pb[i];
        break;
      }
      case TermKind::kDistance: {
        using std::sqrt;
        T pa[3], pb[3];
        internal::SystemPoint(s_.a, x, pa);
        internal::SystemPoint(s_.b, x, pb);
        const T dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
        e[0] = sqrt(dx * dx + dy * dy + dz * dz) - T(s_.z[0]);
        break;
      }
      case TermKind::kPlane: {
        T P[3], plane[4];
        internal::RootPoint(s_.a, x, P);
        internal::RootSurface(s_.surface, x, plane);
        e[0] = plane[0] * P[0] + plane[1] * P[1] + plane[2] * P[2] - plane[3];
        break;
      }
      case TermKind::kLine: {
        T P[3], line[6];
        internal::RootPoint(s_.a, x, P);
        internal::RootSurface(s_.surface, x, line);
        T q[3];
        for (int i = 0; i < 3; ++i) q[i] = P[i] - line[3 + i];
        const T along = q[0] * line[0] + q[1] * line[1] + q[2] * line[2];
        for (int i = 0; i < 3; ++i) e[i] = q[i] - along * line[i];
        break;
      }
      case TermKind::kLineAnchor: {
        const T* l = x[s_.surface.block];
        e[0] = l[0] * l[3] + l[1] * l[4] + l[2] * l[5];
        break;
      }
      default:  // the projections returned above
        break;
    }
    for (int i = 0; i < m; ++i) {
      T acc = T(0.0);
      for (int j = 0; j < m; ++j) acc += s_.W(i, j) * e[j];
      r[i] = acc;
    }
    return true;
  }

 private:
  TermSpec s_;
};

// The cost of a term over parameter blocks of the given ambient sizes (the
// block indices of the spec refer to them). Throws boxplus::Error naming `what`
// for a block index out of range, a block of the wrong size, a noise of the
// wrong dimension, a chain whose table, readings or unknown entries disagree,
// an unknown camera model or non-finite constants.
std::shared_ptr<ceres::CostFunction> MakeJointTerm(const TermSpec& spec,
                                                   const std::vector<int>& block_sizes,
                                                   const std::string& what);

}  // namespace joint

}  // namespace boxplus
