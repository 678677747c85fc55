// Denavit–Hartenberg link maths for kinematic chains (autodiff-safe).
//
// One link (standard DH convention, Denavit & Hartenberg 1955; Spong et al.,
// "Robot Modeling and Control", Sec. 3.2):
//   A(θ, d, a, α) = Rot_z(θ) · Trans_z(d) · Trans_x(a) · Rot_x(α)
// a pose [p, q(x,y,z,w)] mapping the link's next frame to its previous one:
// `prev_from_next`. θ, α in radians; d, a in the chain's length unit. A chain
// of n links gives chain_from_flange = A₁(q₁ + θ₁) … Aₙ(qₙ + θₙ) from joint
// readings qᵢ (θᵢ: the joint's encoder offset).
//
// Modified DH (Craig, "Introduction to Robotics", Sec. 3.4; the row of joint i
// holds α_{i−1}, a_{i−1} of the link before it):
//   A(θ, d, a, α) = Rot_x(α) · Trans_x(a) · Rot_z(θ) · Trans_z(d).
// Both conventions take one row [θ offset, d, a, α] per joint, so a table is
// n × 4 in either; `DHChainPose` composes base_from_chain · A₁ … Aₙ.
#pragma once

#include <cmath>

#include "boxplus/manifolds/se3.h"

namespace boxplus {

namespace kinematics {

// c_from_a = c_from_b ∘ b_from_a for poses [p, q] (apply b_from_a, then c_from_b).
template <typename T>
void Compose(const T* c_from_b, const T* b_from_a, T* c_from_a) {
  T rotated[3];
  QuatRotatePoint(c_from_b + 3, b_from_a, rotated);
  for (int i = 0; i < 3; ++i) c_from_a[i] = c_from_b[i] + rotated[i];
  QuatMultiply(c_from_b + 3, b_from_a + 3, c_from_a + 3);
}

// prev_from_next = Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α), as [p, q].
template <typename T>
void DHLink(const T& theta, const T& d, const T& a, const T& alpha, T* prev_from_next) {
  using std::cos;
  using std::sin;
  prev_from_next[0] = a * cos(theta);
  prev_from_next[1] = a * sin(theta);
  prev_from_next[2] = d;
  // q = q_z(θ) q_x(α), each q = [x, y, z, w]
  const T qz[4] = {T(0.0), T(0.0), sin(theta / T(2.0)), cos(theta / T(2.0))};
  const T qx[4] = {sin(alpha / T(2.0)), T(0.0), T(0.0), cos(alpha / T(2.0))};
  QuatMultiply(qz, qx, prev_from_next + 3);
}

// prev_from_next = Rot_x(α) Trans_x(a) Rot_z(θ) Trans_z(d) (modified DH), as [p, q].
template <typename T>
void ModifiedDHLink(const T& theta, const T& d, const T& a, const T& alpha, T* prev_from_next) {
  using std::cos;
  using std::sin;
  // p = [a, 0, 0] + Rot_x(α) [0, 0, d]
  prev_from_next[0] = a;
  prev_from_next[1] = -sin(alpha) * d;
  prev_from_next[2] = cos(alpha) * d;
  const T qx[4] = {sin(alpha / T(2.0)), T(0.0), T(0.0), cos(alpha / T(2.0))};
  const T qz[4] = {T(0.0), T(0.0), sin(theta / T(2.0)), cos(theta / T(2.0))};
  QuatMultiply(qx, qz, prev_from_next + 3);
}

enum class DHConvention { kStandard = 0, kModified = 1 };

// chain_end = base_from_chain · A₁ … Aₙ with row j of `table` (n × 4, row-major
// [θ offset, d, a, α]) and joint angle θⱼ = joints[j] + table[4j]. All of T.
template <typename T>
void DHChainPose(DHConvention convention, int n, const T* table, const T* joints,
                 const T* base_from_chain, T* base_from_end) {
  T link[7], next[7];
  for (int i = 0; i < 7; ++i) base_from_end[i] = base_from_chain[i];
  for (int j = 0; j < n; ++j) {
    const T* row = table + 4 * j;
    const T theta = joints[j] + row[0];
    if (convention == DHConvention::kStandard) {
      DHLink(theta, row[1], row[2], row[3], link);
    } else {
      ModifiedDHLink(theta, row[1], row[2], row[3], link);
    }
    Compose(base_from_end, link, next);
    for (int i = 0; i < 7; ++i) base_from_end[i] = next[i];
  }
}

}  // namespace kinematics

}  // namespace boxplus
