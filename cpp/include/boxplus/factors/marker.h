// Projection of a marker on a robot's hand through its kinematic chain.
//
// Residual (2):  r = W (π(k, p_in_cam) − z)  (pixels; W = L⁻¹, LLᵀ = Σ)
//   p_in_base = hand2base.fromlocal(p_in_hand)
//   p_in_cam  = x2cam.fromlocal(x2base.tolocal(p_in_base))
// which is the MTKM paper's project_marker (Listing 2): "base" is the link the
// cameras are mounted on (the head), x the reference camera (left), x2base its
// mount (left2head), x2cam the reference→this camera transform (identity for
// the left camera, left2right for the right one), p_in_hand the marker on the
// hand.
//
// Two factors, differing in where hand2base comes from:
//   * KnownKinematicsMarkerFunctor: hand2base is a constant SE3 from forward
//     kinematics. Blocks: k, x2base (SE3 7), p_in_hand (R³), x2cam (SE3 7).
//   * DHMarkerFunctor: hand2base = A₁(q₁) A₂(q₂) … Aₙ(qₙ), the standard
//     Denavit–Hartenberg product with unknown link parameters, from the joint
//     readings q (constants, rad):
//       Aᵢ = Rot_z(qᵢ + θᵢ) · Trans_z(dᵢ) · Trans_x(aᵢ) · Rot_x(αᵢ)
//     Blocks: k, x2base (SE3 7), p_in_hand (R³), x2cam (SE3 7), dh (Rⁿˣ⁴:
//     per joint [θᵢ (joint/encoder offset, rad), dᵢ, aᵢ (lengths), αᵢ (rad)]).
//     A chain that is partly known may be given as a constant prefix
//     base2chain (the chain's first frame in the base frame) and suffix
//     flange2hand.
// Poses [p, q(x,y,z,w)], local → parent, tangent [δp, δθ].
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ceres/dynamic_autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/pinhole.h"

namespace boxplus {

namespace kinematics {

// out = a ∘ b for poses [p, q] (apply b, then a).
template <typename T>
void Compose(const T* a, const T* b, T* out) {
  T rb[3];
  QuatRotatePoint(a + 3, b, rb);
  for (int i = 0; i < 3; ++i) out[i] = a[i] + rb[i];
  QuatMultiply(a + 3, b + 3, out + 3);
}

// The pose [p, q] of one DH link: Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α).
template <typename T>
void DHLink(const T& theta, const T& d, const T& a, const T& alpha, T* out) {
  using std::cos;
  using std::sin;
  const T ct = cos(theta), st = sin(theta);
  out[0] = a * ct;
  out[1] = a * st;
  out[2] = d;
  // q = q_z(θ) q_x(α), each q = [x, y, z, w]
  const T qz[4] = {T(0.0), T(0.0), sin(theta / T(2.0)), cos(theta / T(2.0))};
  const T qx[4] = {sin(alpha / T(2.0)), T(0.0), T(0.0), cos(alpha / T(2.0))};
  QuatMultiply(qz, qx, out + 3);
}

}  // namespace kinematics

template <class Model>
class KnownKinematicsMarkerFunctor {
 public:
  KnownKinematicsMarkerFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
                               const Eigen::Matrix<double, 7, 1>& hand2base)
      : z_(z), W_(sqrt_info), hand2base_(hand2base) {}

  template <typename T>
  bool operator()(const T* k, const T* x2base, const T* p_in_hand, const T* x2cam,
                  T* residual) const {
    T h2b[7];
    for (int i = 0; i < 7; ++i) h2b[i] = T(hand2base_[i]);
    T p_in_base[3], p_in_cam[3];
    QuatRotatePoint(h2b + 3, p_in_hand, p_in_base);
    for (int i = 0; i < 3; ++i) p_in_base[i] += h2b[i];
    camera::ChainToCam(x2base, x2cam, p_in_base, p_in_cam);
    camera::ProjectionResidual<Model>(k, p_in_cam, z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Eigen::Vector2d& z,
                                                     const Eigen::Matrix2d& W,
                                                     const Eigen::Matrix<double, 7, 1>& hand2base) {
    return std::make_shared<ceres::AutoDiffCostFunction<KnownKinematicsMarkerFunctor, 2,
                                                        Model::kSize, 7, 3, 7>>(
        new KnownKinematicsMarkerFunctor(z, W, hand2base));
  }

 private:
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::Matrix<double, 7, 1> hand2base_;
};

template <class Model>
class DHMarkerFunctor {
 public:
  DHMarkerFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
                  const Eigen::VectorXd& joints, const Eigen::Matrix<double, 7, 1>& base2chain,
                  const Eigen::Matrix<double, 7, 1>& flange2hand)
      : z_(z), W_(sqrt_info), q_(joints), prefix_(base2chain), suffix_(flange2hand) {}

  // parameters: k, x2base, p_in_hand, x2cam, dh
  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* k = parameters[0];
    const T* x2base = parameters[1];
    const T* p_in_hand = parameters[2];
    const T* x2cam = parameters[3];
    const T* dh = parameters[4];
    T pose[7], link[7], next[7];
    for (int i = 0; i < 7; ++i) pose[i] = T(prefix_[i]);
    for (Eigen::Index j = 0; j < q_.size(); ++j) {
      const T* l = dh + 4 * j;
      kinematics::DHLink(T(q_[j]) + l[0], l[1], l[2], l[3], link);
      kinematics::Compose(pose, link, next);
      std::copy(next, next + 7, pose);
    }
    T suffix[7];
    for (int i = 0; i < 7; ++i) suffix[i] = T(suffix_[i]);
    kinematics::Compose(pose, suffix, next);  // hand2base
    T p_in_base[3], p_in_cam[3];
    QuatRotatePoint(next + 3, p_in_hand, p_in_base);
    for (int i = 0; i < 3; ++i) p_in_base[i] += next[i];
    camera::ChainToCam(x2base, x2cam, p_in_base, p_in_cam);
    camera::ProjectionResidual<Model>(k, p_in_cam, z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(const Eigen::Vector2d& z,
                                                     const Eigen::Matrix2d& W,
                                                     const Eigen::VectorXd& joints,
                                                     const Eigen::Matrix<double, 7, 1>& base2chain,
                                                     const Eigen::Matrix<double, 7, 1>& flange2hand) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<DHMarkerFunctor, 8>(
        new DHMarkerFunctor(z, W, joints, base2chain, flange2hand));
    cost->AddParameterBlock(Model::kSize);
    cost->AddParameterBlock(7);
    cost->AddParameterBlock(3);
    cost->AddParameterBlock(7);
    cost->AddParameterBlock(4 * static_cast<int>(joints.size()));
    cost->SetNumResiduals(2);
    return std::shared_ptr<ceres::CostFunction>(cost);
  }

 private:
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::VectorXd q_;
  Eigen::Matrix<double, 7, 1> prefix_, suffix_;
};

std::shared_ptr<ceres::CostFunction> MakeKnownKinematicsMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
    const Eigen::Matrix<double, 7, 1>& hand2base);

// Throws boxplus::Error for an empty joint vector or a non-finite reading.
std::shared_ptr<ceres::CostFunction> MakeDHMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const Eigen::Matrix2d& sqrt_info,
    const Eigen::VectorXd& joints, const Eigen::Matrix<double, 7, 1>& base2chain,
    const Eigen::Matrix<double, 7, 1>& flange2hand);

}  // namespace boxplus
