// Projection of a marker on a robot's hand through its kinematic chain.
//
// Residual (2):  r = W (π(k, p_in_cam) − z)  (pixels; WᵀW = Σ⁻¹, the NoiseModel)
//   p_in_base = base_from_hand · p_in_hand
//   p_in_cam  = cam_from_rig · base_from_rig⁻¹ · p_in_base   (camera::ChainToCam)
// which is the MTKM paper's project_marker (Listing 2): "base" is the link the
// cameras are mounted on (the head), rig the reference camera (left),
// base_from_rig its mount (MTKM's left2head), cam_from_rig the reference→this
// camera transform (identity for the left camera, right_from_left for the
// right one), p_in_hand the marker on the hand.
//
// Two factors, differing in where base_from_hand comes from:
//   * KnownKinematicsMarkerFunctor: base_from_hand is a constant SE3 from
//     forward kinematics. Blocks: k, base_from_rig (SE3 7), p_in_hand (R³),
//     cam_from_rig (SE3 7).
//   * DHMarkerFunctor: base_from_hand = base_from_chain · A₁(q₁ + θ₁) … Aₙ(qₙ + θₙ)
//     · flange_from_hand, the Denavit–Hartenberg product (dh.h) with unknown
//     link parameters from the joint readings q (constants, rad).
//     Blocks: k, base_from_rig (SE3 7), p_in_hand (R³), cam_from_rig (SE3 7),
//     dh (R⁴ⁿ: per joint [θᵢ (joint/encoder offset, rad), dᵢ, aᵢ (lengths),
//     αᵢ (rad)]). The constant prefix base_from_chain (the chain's first frame
//     in the base frame) and suffix flange_from_hand (the hand in the last
//     link's frame) hold the known part of the chain.
// Poses [p, q(x,y,z,w)], tangent [δp, δθ]; lengths in the chain's unit (metres).
#pragma once

#include <algorithm>
#include <memory>
#include <string>

#include <ceres/autodiff_cost_function.h>
#include <ceres/dynamic_autodiff_cost_function.h>

#include <Eigen/Core>

#include "boxplus/factors/camera/point_projection.h"
#include "boxplus/factors/kinematics/dh.h"

namespace boxplus {

namespace kinematics {

// r = W (π(k, cam_from_rig · base_from_rig⁻¹ · base_from_hand · p_in_hand) − z).
template <class Model, typename T>
void MarkerResidual(const T* k, const T* base_from_rig, const T* p_in_hand, const T* cam_from_rig,
                    const T* base_from_hand, const double* z, const Eigen::Matrix2d& W,
                    T* residual) {
  T p_in_base[3], p_in_cam[3];
  QuatRotatePoint(base_from_hand + 3, p_in_hand, p_in_base);
  for (int i = 0; i < 3; ++i) p_in_base[i] += base_from_hand[i];
  camera::ChainToCam(base_from_rig, cam_from_rig, p_in_base, p_in_cam);
  camera::ProjectionResidual<Model>(k, p_in_cam, z, W, residual);
}

}  // namespace kinematics

template <class Model>
class KnownKinematicsMarkerFunctor {
 public:
  KnownKinematicsMarkerFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
                               const Eigen::Matrix<double, 7, 1>& base_from_hand)
      : z_(z), W_(W), base_from_hand_(base_from_hand) {}

  template <typename T>
  bool operator()(const T* k, const T* base_from_rig, const T* p_in_hand, const T* cam_from_rig,
                  T* residual) const {
    T base_from_hand[7];
    for (int i = 0; i < 7; ++i) base_from_hand[i] = T(base_from_hand_[i]);
    kinematics::MarkerResidual<Model>(k, base_from_rig, p_in_hand, cam_from_rig, base_from_hand,
                                      z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(
      const Eigen::Vector2d& z, const Eigen::Matrix2d& W,
      const Eigen::Matrix<double, 7, 1>& base_from_hand) {
    return std::make_shared<
        ceres::AutoDiffCostFunction<KnownKinematicsMarkerFunctor, 2, Model::kSize, 7, 3, 7>>(
        new KnownKinematicsMarkerFunctor(z, W, base_from_hand));
  }

 private:
  Eigen::Vector2d z_;
  Eigen::Matrix2d W_;
  Eigen::Matrix<double, 7, 1> base_from_hand_;
};

template <class Model>
class DHMarkerFunctor {
 public:
  DHMarkerFunctor(const Eigen::Vector2d& z, const Eigen::Matrix2d& W, const Eigen::VectorXd& joints,
                  const Eigen::Matrix<double, 7, 1>& base_from_chain,
                  const Eigen::Matrix<double, 7, 1>& flange_from_hand)
      : z_(z),
        W_(W),
        q_(joints),
        base_from_chain_(base_from_chain),
        flange_from_hand_(flange_from_hand) {}

  // parameters: k, base_from_rig, p_in_hand, cam_from_rig, dh
  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* dh = parameters[4];
    T base_from_link[7], link[7], next[7];
    for (int i = 0; i < 7; ++i) base_from_link[i] = T(base_from_chain_[i]);
    for (Eigen::Index j = 0; j < q_.size(); ++j) {
      const T* l = dh + 4 * j;
      kinematics::DHLink(T(q_[j]) + l[0], l[1], l[2], l[3], link);
      kinematics::Compose(base_from_link, link, next);
      std::copy(next, next + 7, base_from_link);
    }
    T flange_from_hand[7], base_from_hand[7];
    for (int i = 0; i < 7; ++i) flange_from_hand[i] = T(flange_from_hand_[i]);
    kinematics::Compose(base_from_link, flange_from_hand, base_from_hand);
    kinematics::MarkerResidual<Model>(parameters[0], parameters[1], parameters[2], parameters[3],
                                      base_from_hand, z_.data(), W_, residual);
    return true;
  }

  static std::shared_ptr<ceres::CostFunction> Create(
      const Eigen::Vector2d& z, const Eigen::Matrix2d& W, const Eigen::VectorXd& joints,
      const Eigen::Matrix<double, 7, 1>& base_from_chain,
      const Eigen::Matrix<double, 7, 1>& flange_from_hand) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<DHMarkerFunctor, 8>(
        new DHMarkerFunctor(z, W, joints, base_from_chain, flange_from_hand));
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
  Eigen::Matrix<double, 7, 1> base_from_chain_, flange_from_hand_;
};

// `noise` of dimension 2 (pixels). Throws boxplus::Error for an unknown camera
// model, another noise dimension or non-finite input.
std::shared_ptr<ceres::CostFunction> MakeKnownKinematicsMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const NoiseModel& noise,
    const Eigen::Matrix<double, 7, 1>& base_from_hand);

// Also throws for an empty joint vector.
std::shared_ptr<ceres::CostFunction> MakeDHMarkerFactor(
    const std::string& model, const Eigen::Vector2d& z, const NoiseModel& noise,
    const Eigen::VectorXd& joints, const Eigen::Matrix<double, 7, 1>& base_from_chain,
    const Eigen::Matrix<double, 7, 1>& flange_from_hand);

}  // namespace boxplus
