// SE-Sync's chordal residual of a relative-pose measurement (Rosen et al.,
// IJRR 2019, Eq. 9-10) — its own residual kind, not an error of
// Δ = z⁻¹(xᵢ⁻¹xⱼ) like the conventions of relative_pose.h. The objective
//   f = Σ κᵢⱼ‖Rⱼ − RᵢR̃ᵢⱼ‖²_F + τᵢⱼ‖tⱼ − tᵢ − Rᵢt̃ᵢⱼ‖²
// with isotropic precisions taken from each noise's information Ω (order
// [translation, rotation], as g2o files store it), as SE-Sync's read_g2o_file
// does:
//   3D  τ = 3 / tr(Ω_t⁻¹),  κ = 3 / (2 tr(Ω_R⁻¹))
//   2D  τ = 2 / tr(Ω_t⁻¹),  κ = Ω_θθ
// Residual (3D 3 + 9, 2D 2 + 4), so that Σ‖r‖² = f:
//   r = W e,  e = [tⱼ − tᵢ − Rᵢt̃ᵢⱼ,  vec(Rⱼ − RᵢR̃ᵢⱼ)]   (vec row by row)
//   W = diag(√τ·I_d, √κ·I_d²)                           (ChordalNoise)
// e is in the units of the poses (translation) and unitless (rotation); a
// problem that registers ChordalNoise(noise) un-whitens r to it.
// Ambient layouts as the other pose factors: SE2 [x, y, θ], SE3 [p, qx, qy,
// qz, qw] (unit quaternion, as SE3's ⊞ keeps it). Blocks x_i, x_j; autodiff.
#pragma once

#include <memory>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "boxplus/noise.h"

namespace boxplus {

struct ChordalPrecisions {
  double tau;
  double kappa;
};

// τ and κ of a 3-dim (2D) or 6-dim (3D) noise's information Ω; throws
// boxplus::Error for other dimensions.
ChordalPrecisions ChordalPrecisionsOf(const NoiseModel& noise);
// The same from the information matrix Ω itself (3 × 3 or 6 × 6).
ChordalPrecisions ChordalPrecisionsOfInformation(const Eigen::MatrixXd& information);
// The whitening W above (dimension 6 or 12) of the chordal residual of a
// measurement with the 3- or 6-dim `noise`.
NoiseModel ChordalNoise(const NoiseModel& noise);

// Row-major rotation matrix of a unit quaternion [x, y, z, w].
template <typename T>
void QuatToRotationMatrix(const T* q, T* R) {
  const T x = q[0], y = q[1], z = q[2], w = q[3];
  R[0] = T(1.0) - T(2.0) * (y * y + z * z);
  R[1] = T(2.0) * (x * y - z * w);
  R[2] = T(2.0) * (x * z + y * w);
  R[3] = T(2.0) * (x * y + z * w);
  R[4] = T(1.0) - T(2.0) * (x * x + z * z);
  R[5] = T(2.0) * (y * z - x * w);
  R[6] = T(2.0) * (x * z - y * w);
  R[7] = T(2.0) * (y * z + x * w);
  R[8] = T(1.0) - T(2.0) * (x * x + y * y);
}

// r (6) for SE(2) poses xi, xj and z = [x, y, θ].
template <typename T>
void ChordalRelativePose2DResidual(const T* xi, const T* xj, const double* z,
                                   const ChordalPrecisions& p, T* r) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T ci = cos(xi[2]), si = sin(xi[2]);
  const double st = sqrt(p.tau), sk = sqrt(p.kappa);
  r[0] = st * (xj[0] - xi[0] - (ci * z[0] - si * z[1]));
  r[1] = st * (xj[1] - xi[1] - (si * z[0] + ci * z[1]));
  const double cz = std::cos(z[2]), sz = std::sin(z[2]);
  const T c = ci * cz - si * sz, s = si * cz + ci * sz;  // RᵢR̃ᵢⱼ = R(θᵢ + θ_z)
  const T cj = cos(xj[2]), sj = sin(xj[2]);
  r[2] = sk * (cj - c);
  r[3] = -sk * (sj - s);
  r[4] = sk * (sj - s);
  r[5] = sk * (cj - c);
}

// r (12) for SE(3) poses xi, xj and z = [t, qx, qy, qz, qw] (unit).
template <typename T>
void ChordalRelativePose3DResidual(const T* xi, const T* xj, const double* z,
                                   const ChordalPrecisions& p, T* r) {
  using std::sqrt;
  T Ri[9], Rj[9];
  QuatToRotationMatrix(xi + 3, Ri);
  QuatToRotationMatrix(xj + 3, Rj);
  double Rz[9];
  QuatToRotationMatrix(z + 3, Rz);
  const double st = sqrt(p.tau), sk = sqrt(p.kappa);
  for (int a = 0; a < 3; ++a) {
    T rt = T(0.0);
    for (int b = 0; b < 3; ++b) rt += Ri[3 * a + b] * z[b];
    r[a] = st * (xj[a] - xi[a] - rt);
    for (int c = 0; c < 3; ++c) {
      T m = T(0.0);
      for (int b = 0; b < 3; ++b) m += Ri[3 * a + b] * Rz[3 * b + c];
      r[3 + 3 * a + c] = sk * (Rj[3 * a + c] - m);
    }
  }
}

// Autodiff cost functions. z: [x, y, θ] / [t, q] (q normalised here);
// `noise` the measurement's (3- or 6-dim) model, from which τ and κ are
// taken; register the measurement with ChordalNoise(noise).
std::shared_ptr<ceres::CostFunction> MakeChordalRelativePose2D(const Eigen::Vector3d& z,
                                                               const NoiseModel& noise);
std::shared_ptr<ceres::CostFunction> MakeChordalRelativePose3D(const Eigen::Matrix<double, 7, 1>& z,
                                                               const NoiseModel& noise);

}  // namespace boxplus
