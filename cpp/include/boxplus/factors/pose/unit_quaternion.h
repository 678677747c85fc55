// Normalisation of quaternions read from files or given by callers, [x, y, z, w].
//
// q / ‖q‖ computed naively overflows for components near 1e155 (‖q‖² = inf,
// q / inf = 0: the quaternion [0, 0, 0, 1e200] became [0, 0, 0, 0]) and
// underflows below 1e-155. Scaling by the largest |component| first keeps
// ‖q / max|qᵢ|‖ in [1, 2], so every finite non-zero q normalises exactly to
// the rotation it means.
#pragma once

#include <cmath>

namespace boxplus {

// out = q / ‖q‖ (out may alias q). False, out untouched, if q is zero or not
// finite.
inline bool NormalizeQuaternion(const double* q, double* out) {
  double m = 0.0;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(q[i])) return false;
    m = std::fmax(m, std::fabs(q[i]));
  }
  if (!(m > 0.0)) return false;
  double s[4], n2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    s[i] = q[i] / m;
    n2 += s[i] * s[i];
  }
  const double n = std::sqrt(n2);
  for (int i = 0; i < 4; ++i) out[i] = s[i] / n;
  return true;
}

// An angle wrapped into [−π, π) exactly, for every finite double.
inline double WrapAngleExact(double a) {
  if (a >= -M_PI && a < M_PI) return a;  // in range: the same bits
  // remainder(a, 2π) with the double nearest 2π is off by a/2π × 2.4e-16 (4e-5 rad
  // at 1e12 rad, every digit beyond 1e16); the C library's sin and cos reduce their
  // argument exactly (Payne–Hanek), so atan2(sin a, cos a) is a mod 2π to an ulp
  // for every finite double (checked against 2000-bit arithmetic up to 1e300).
  const double r = std::atan2(std::sin(a), std::cos(a));
  return r >= M_PI ? -M_PI : r;
}

}  // namespace boxplus
