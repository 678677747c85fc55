// Every built-in factor: Jacobians (autodiff, mapped to the tangent space by
// ⊞'s Jacobian) against central differences through ⊞, at random points; plus
// a few exact values (board = stacked points, a DH link, gravity, disparity).
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "boxplus/errors.h"
#include "boxplus/factors/camera/board.h"
#include "boxplus/factors/camera/point_projection.h"
#include "boxplus/factors/depth/disparity.h"
#include "boxplus/factors/imu/gravity.h"
#include "boxplus/factors/kinematics/dh.h"
#include "boxplus/factors/kinematics/marker.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/factors/pose/observed_point.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/manifolds.h"

namespace boxplus {
namespace {

using Pose = Eigen::Matrix<double, 7, 1>;

Pose RandomPose(std::mt19937& rng, double spread = 0.3) {
  std::normal_distribution<double> g;
  Eigen::Vector4d q(g(rng), g(rng), g(rng), 4.0 + g(rng));  // near identity: points stay in front
  q.normalize();
  Pose x;
  x << spread * g(rng), spread * g(rng), spread * g(rng), q;
  return x;
}

// A parameter block: its value and whether ⊞ is SE(3)'s (else Rⁿ's +).
struct Block {
  Eigen::VectorXd x;
  bool pose;
};

Eigen::VectorXd Eval(const ceres::CostFunction& cost, const std::vector<Block>& blocks) {
  std::vector<const double*> ptrs;
  for (const auto& b : blocks) ptrs.push_back(b.x.data());
  Eigen::VectorXd r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(ptrs.data(), r.data(), nullptr));
  return r;
}

// Tangent Jacobians of `cost` (autodiff × PlusJacobian) against central
// differences of r(x ⊞ ±h eⱼ).
void ExpectJacobiansMatch(const ceres::CostFunction& cost, std::vector<Block> blocks,
                          double tol = 1e-6) {
  const int m = cost.num_residuals();
  std::vector<const double*> ptrs;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J;
  for (const auto& b : blocks) {
    ptrs.push_back(b.x.data());
    J.emplace_back(m, b.x.size());
  }
  std::vector<double*> jptrs;
  for (auto& j : J) jptrs.push_back(j.data());
  Eigen::VectorXd r(m);
  ASSERT_TRUE(cost.Evaluate(ptrs.data(), r.data(), jptrs.data()));
  SE3Manifold se3;
  for (size_t k = 0; k < blocks.size(); ++k) {
    const int n = blocks[k].pose ? 6 : static_cast<int>(blocks[k].x.size());
    Eigen::MatrixXd Jt = J[k];
    if (blocks[k].pose) {
      Eigen::Matrix<double, 7, 6, Eigen::RowMajor> P;
      se3.PlusJacobian(blocks[k].x.data(), P.data());
      Jt = J[k] * P;
    }
    for (int j = 0; j < n; ++j) {
      const double h = 1e-6;
      Eigen::VectorXd rs[2];
      for (int s = 0; s < 2; ++s) {
        std::vector<Block> moved = blocks;
        Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
        d[j] = s == 0 ? h : -h;
        if (blocks[k].pose) {
          se3.Plus(blocks[k].x.data(), d.data(), moved[k].x.data());
        } else {
          moved[k].x += d;
        }
        rs[s] = Eval(cost, moved);
      }
      const Eigen::VectorXd numeric = (rs[0] - rs[1]) / (2 * h);
      const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
      EXPECT_LT((Jt.col(j) - numeric).cwiseAbs().maxCoeff(), tol * scale)
          << "block " << k << " direction " << j << "\nautodiff " << Jt.col(j).transpose()
          << "\nnumeric  " << numeric.transpose();
    }
  }
}

Eigen::VectorXd Intrinsics(const std::string& model) {
  Eigen::VectorXd k(CameraModelSize(model));
  if (model == "simple_radial") {
    k << 500, 320, 240, -0.2;
  } else {
    k.head<4>() << 510, 505, 320, 240;
    if (k.size() > 4) k.tail(k.size() - 4).setConstant(0.02);
    if (k.size() > 4) k[4] = -0.25;
  }
  return k;
}

// A full (non-diagonal) 2×2 square-root information, so that whitening mixes
// the two pixel coordinates.
NoiseModel W2() {
  Eigen::Matrix2d W;
  W << 2.0, 0.3, 0.0, 1.5;
  return NoiseModel::SqrtInformation(W);
}

TEST(BoardFactor, JacobiansAndEqualsStackedPoints) {
  std::mt19937 rng(1);
  for (const std::string model : {"simple_radial", "pinhole", "radial1", "radial2", "opencv5"}) {
    BoardPoints p(4, 3);
    p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.1;
    BoardPixels z(4, 2);
    z << 300, 200, 350, 210, 310, 260, 360, 250;
    Pose world_from_rig = RandomPose(rng);
    world_from_rig.head<3>() << 0.5, 0.5, -5;  // the camera 5 units in front of the board
    const Pose cam_from_rig = RandomPose(rng, 0.1);
    auto board = MakeBoardFactor(model, z, W2(), p);
    std::vector<Block> blocks = {
        {Intrinsics(model), false}, {world_from_rig, true}, {cam_from_rig, true}};
    ExpectJacobiansMatch(*board, blocks);
    const Eigen::VectorXd r = Eval(*board, blocks);
    for (int j = 0; j < 4; ++j) {
      auto point =
          MakePointProjectionFactor(model, z.row(j).transpose(), W2(), p.row(j).transpose());
      EXPECT_LT((Eval(*point, blocks) - r.segment<2>(2 * j)).norm(), 1e-9) << model;
    }
  }
  EXPECT_THROW(MakeBoardFactor("fisheye", {}, W2(), {}), Error);
}

TEST(MarkerFactor, KnownKinematicsJacobians) {
  std::mt19937 rng(2);
  Pose base_from_hand = RandomPose(rng);
  base_from_hand.head<3>() << 0.1, 0.2, 1.5;
  auto f = MakeKnownKinematicsMarkerFactor("radial2", {300, 200}, W2(), base_from_hand);
  ExpectJacobiansMatch(*f, {{Intrinsics("radial2"), false},
                            {RandomPose(rng), true},
                            {Eigen::Vector3d(0.05, -0.02, 0.1), false},
                            {RandomPose(rng, 0.1), true}});
}

TEST(MarkerFactor, DHJacobiansAndOneLink) {
  std::mt19937 rng(3);
  Eigen::VectorXd q(3);
  q << 0.3, -0.5, 0.8;
  Eigen::VectorXd dh(12);
  dh << 0.01, 0.2, 0.3, 0.5, -0.02, 0.0, 0.4, -0.3, 0.0, 0.1, 0.2, 0.2;
  Pose prefix = Pose::Zero(), suffix = Pose::Zero();
  prefix[6] = suffix[6] = 1;
  prefix[2] = 2.0;  // the chain starts 2 units in front of the camera
  auto f = MakeDHMarkerFactor("opencv5", {300, 200}, W2(), q, prefix, suffix);
  ExpectJacobiansMatch(*f, {{Intrinsics("opencv5"), false},
                            {RandomPose(rng, 0.05), true},
                            {Eigen::Vector3d(0.05, -0.02, 0.1), false},
                            {RandomPose(rng, 0.05), true},
                            {dh, false}});
  // One link: Rot_z(90°) Trans_x(1) takes the origin to (0, 1, 0).
  double link[7];
  kinematics::DHLink(kPi / 2, 0.0, 1.0, 0.0, link);
  EXPECT_NEAR(link[0], 0.0, 1e-12);
  EXPECT_NEAR(link[1], 1.0, 1e-12);
  EXPECT_THROW(MakeDHMarkerFactor("opencv5", {0, 0}, W2(), Eigen::VectorXd(), prefix, suffix),
               Error);
}

TEST(GravityFactor, JacobiansAndLevelledValue) {
  std::mt19937 rng(4);
  const NoiseModel W = NoiseModel::Isotropic(3, 1.0 / 3.0);
  for (const std::string model : {"rotation", "scale", "scale_bias"}) {
    auto f = MakeGravityFactor(model, {0.1, -0.2, 9.7}, W, {0, 0, -9.81});
    std::vector<Block> blocks = {{RandomPose(rng), true}, {RandomPose(rng), true}};
    if (GravityModelSize(model) > 0) {
      Eigen::VectorXd a(GravityModelSize(model));
      a.setConstant(0.05);
      a[0] = 1.02;
      blocks.push_back({a, false});
    }
    ExpectJacobiansMatch(*f, blocks);
  }
  // Identity rotations: the IMU reads g_in_world itself.
  auto f = MakeGravityFactor("rotation", {0, 0, -9.81}, W, {0, 0, -9.81});
  Pose id = Pose::Zero();
  id[6] = 1;
  EXPECT_LT(Eval(*f, {{id, true}, {id, true}}).norm(), 1e-12);
  EXPECT_THROW(MakeGravityFactor("tilt", {0, 0, 0}, W, {0, 0, 1}), Error);
}

TEST(RelativePoseFactor, JacobiansAndZeroAtTruth) {
  std::mt19937 rng(5);
  Eigen::Matrix<double, 6, 6> W = Eigen::Matrix<double, 6, 6>::Identity();
  W(0, 4) = 0.3;
  const Pose a = RandomPose(rng), b = RandomPose(rng);
  SE3 A = SE3::FromAmbient(a.data()), B = SE3::FromAmbient(b.data());
  const SE3 b2a = A.inverse() * B;
  const auto compound = PoseErrorConvention::kCompound;
  auto f = MakeRelativePose3D(b2a.ambient(), NoiseModel::SqrtInformation(W), compound);
  EXPECT_LT(Eval(*f, {{a, true}, {b, true}}).norm(), 1e-12);
  ExpectJacobiansMatch(
      *MakeRelativePose3D(RandomPose(rng), NoiseModel::SqrtInformation(W), compound),
      {{a, true}, {b, true}});
}

// SE-Sync's chordal factor: Jacobians, zero at the truth, and ‖r‖² against
// its definition with τ, κ from Ω (SE-Sync's read_g2o_file).
TEST(ChordalRelativePoseFactor, JacobiansZeroAtTruthAndValue3D) {
  std::mt19937 rng(11);
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Identity();
  info.topLeftCorner<3, 3>() << 4, 1, 0, 1, 3, 0.5, 0, 0.5, 2;
  info.bottomRightCorner<3, 3>() << 9, 0, 1, 0, 8, 0, 1, 0, 7;
  const double tau = 3.0 / info.topLeftCorner<3, 3>().inverse().trace();
  const double kappa = 3.0 / (2.0 * info.bottomRightCorner<3, 3>().inverse().trace());
  const NoiseModel noise = NoiseModel::Information(info);
  const ChordalPrecisions p = ChordalPrecisionsOf(noise);
  EXPECT_NEAR(p.tau, tau, 1e-12);
  EXPECT_NEAR(p.kappa, kappa, 1e-12);
  const Pose a = RandomPose(rng, 2.0), b = RandomPose(rng, 2.0), z = RandomPose(rng, 2.0);
  const SE3 A = SE3::FromAmbient(a.data()), B = SE3::FromAmbient(b.data());
  const SE3 Z = SE3::FromAmbient(z.data());
  auto truth = MakeChordalRelativePose3D((A.inverse() * B).ambient(), noise);
  EXPECT_EQ(truth->num_residuals(), 12);
  EXPECT_LT(Eval(*truth, {{a, true}, {b, true}}).norm(), 1e-12);
  auto f = MakeChordalRelativePose3D(z, noise);
  ExpectJacobiansMatch(*f, {{a, true}, {b, true}});
  const Eigen::Matrix3d Ri = A.rotation().matrix(), Rj = B.rotation().matrix();
  const Eigen::Matrix3d Rz = Z.rotation().matrix();
  const Eigen::Vector3d t = B.pos() - A.pos() - Ri * Z.pos();
  const double expected = kappa * (Rj - Ri * Rz).squaredNorm() + tau * t.squaredNorm();
  const Eigen::VectorXd r = Eval(*f, {{a, true}, {b, true}});
  EXPECT_NEAR(r.squaredNorm(), expected, 1e-10 * expected);
  // ChordalNoise un-whitens r to the chordal error e = [t, vec(Rj − Ri Rz)]
  // (rows of the matrix one after the other), in the poses' units.
  const NoiseModel chordal = ChordalNoise(noise);
  ASSERT_EQ(chordal.dim(), 12);
  Eigen::VectorXd e(12);
  e.head<3>() = t;
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> D = Rj - Ri * Rz;
  e.tail<9>() = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(D.data());
  EXPECT_LT((chordal.Unwhiten(r) - e).norm(), 1e-12 * (1 + e.norm()));
  EXPECT_EQ(chordal.Whiten(chordal.Unwhiten(r)), r);
  // The convention's name selects this factor.
  EXPECT_EQ(MakeRelativePose3D(z, noise, ParsePoseErrorConvention("chordal"))->num_residuals(), 12);
}

TEST(ChordalRelativePoseFactor, JacobiansZeroAtTruthAndValue2D) {
  std::mt19937 rng(12);
  std::normal_distribution<double> g;
  Eigen::Matrix3d info;
  info << 50, 20, 3, 20, 30, 1, 3, 1, 200;
  const NoiseModel noise = NoiseModel::Information(info);
  const double tau = 2.0 / info.topLeftCorner<2, 2>().inverse().trace(), kappa = info(2, 2);
  const auto rot = [](double th) { return Eigen::Rotation2Dd(th).toRotationMatrix(); };
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd a(3), b(3);
    a << 3 * g(rng), 3 * g(rng), 3 * g(rng);
    b << 3 * g(rng), 3 * g(rng), 3 * g(rng);
    Eigen::Vector3d z(g(rng), g(rng), 3 * g(rng));
    auto f = MakeChordalRelativePose2D(z, noise);
    EXPECT_EQ(f->num_residuals(), 6);
    ExpectJacobiansMatch(*f, {{a, false}, {b, false}});
    const Eigen::Vector2d t = b.head<2>() - a.head<2>() - rot(a[2]) * z.head<2>();
    const double expected =
        kappa * (rot(b[2]) - rot(a[2]) * rot(z[2])).squaredNorm() + tau * t.squaredNorm();
    EXPECT_NEAR(Eval(*f, {{a, false}, {b, false}}).squaredNorm(), expected, 1e-10 * expected);
    // Zero at the truth: z = a⁻¹b.
    Eigen::Vector3d zt;
    zt.head<2>() = rot(a[2]).transpose() * (b.head<2>() - a.head<2>());
    zt[2] = b[2] - a[2];
    EXPECT_LT(Eval(*MakeChordalRelativePose2D(zt, noise), {{a, false}, {b, false}}).norm(), 1e-12);
  }
  EXPECT_EQ(MakeRelativePose2D(Eigen::Vector3d(1, 0, 0), noise, PoseErrorConvention::kSESync)
                ->num_residuals(),
            6);
  EXPECT_THROW(MakeChordalRelativePose2D(Eigen::Vector3d(1, 0, 0), NoiseModel::Information(-info)),
               Error);
  EXPECT_EQ(ChordalNoise(noise).dim(), 6);
  EXPECT_THROW(ChordalNoise(NoiseModel::Unit(4)), Error);
  EXPECT_STREQ(ToString(ParsePoseErrorConvention("sesync")), "sesync");
}

TEST(PointFactor, Jacobians) {
  std::mt19937 rng(6);
  const Eigen::Matrix3d W = Eigen::Vector3d(1, 2, 3).asDiagonal();
  ExpectJacobiansMatch(
      *MakeObservedPointOnRig({0.1, 0.2, 1.0}, NoiseModel::SqrtInformation(W), {0.3, -0.2, 2.0}),
      {{RandomPose(rng), true}, {RandomPose(rng), true}});
  ExpectJacobiansMatch(
      *MakeObservedLandmarkOnRig({0.1, 0.2, 1.0}, NoiseModel::SqrtInformation(W)),
      {{RandomPose(rng), true}, {RandomPose(rng), true}, {Eigen::Vector3d(0.3, -0.2, 2.0), false}});
}

TEST(DisparityFactor, JacobiansAndValue) {
  std::mt19937 rng(7);
  Pose world_from_rig = RandomPose(rng);
  world_from_rig.head<3>() << 0.2, 0.1, -2.0;
  Eigen::VectorXd ab(2);
  ab << 580.0, 1090.0;
  ExpectJacobiansMatch(*MakeDisparityFactor(800.0, NoiseModel::Isotropic(1, 0.5), {0.3, 0.4, 0.0}),
                       {{world_from_rig, true}, {RandomPose(rng, 0.05), true}, {ab, false}});
  Pose id = Pose::Zero();
  id[6] = 1;
  Pose board_from_cam = id;
  board_from_cam[2] = -2.0;  // board point (0,0,0) at depth 2
  auto f = MakeDisparityFactor(580.0 / 2 + 1090.0, NoiseModel::Unit(1), {0, 0, 0});
  EXPECT_NEAR(Eval(*f, {{board_from_cam, true}, {id, true}, {ab, false}})[0], 0.0, 1e-9);
  // σ = 0.5 doubles the residual of a disparity 1 unit off.
  auto off = MakeDisparityFactor(580.0 / 2 + 1089.0, NoiseModel::Isotropic(1, 0.5), {0, 0, 0});
  EXPECT_NEAR(Eval(*off, {{board_from_cam, true}, {id, true}, {ab, false}})[0], 2.0, 1e-9);
  EXPECT_THROW(MakeDisparityFactor(1.0, NoiseModel::Unit(2), {0, 0, 0}), Error);
  EXPECT_THROW(MakeDisparityFactor(1.0, NoiseModel::Isotropic(1, 0.0), {0, 0, 0}), Error);
}

// Every sensor factor whitens with its NoiseModel: the four ways of giving the
// same Σ (σᵢ for a diagonal Σ, Σ, Ω = Σ⁻¹, W = L⁻¹) give the same ‖r‖², and that
// equals eᵀ Σ⁻¹ e with e the error of the factor under unit noise (block by
// block for a board).
TEST(SensorFactors, NoiseInAllFormsGivesTheSameCost) {
  std::mt19937 rng(8);
  using Make = std::function<std::shared_ptr<ceres::CostFunction>(const NoiseModel&)>;
  struct Case {
    std::string name;
    int dim;
    Make make;
    std::vector<Block> blocks;
  };
  Pose world_from_rig = RandomPose(rng);
  world_from_rig.head<3>() << 0.5, 0.5, -5;
  const Pose cam_from_rig = RandomPose(rng, 0.1);
  BoardPoints p(3, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0.1;
  BoardPixels z(3, 2);
  z << 300, 200, 350, 210, 310, 260;
  Eigen::VectorXd q(2), dh(8), accel(4), ab(2);
  q << 0.3, -0.5;
  dh << 0.01, 0.2, 0.3, 0.5, -0.02, 0.0, 0.4, -0.3;
  accel << 1.02, 0.05, -0.03, 0.1;
  ab << 580.0, 1090.0;
  Pose identity = Pose::Zero();
  identity[6] = 1;
  Pose base_from_chain = identity;
  base_from_chain[2] = 2.0;
  const Eigen::Vector3d p_in_hand(0.05, -0.02, 0.1);
  const std::vector<Block> camera = {
      {Intrinsics("opencv5"), false}, {world_from_rig, true}, {cam_from_rig, true}};
  const std::vector<Block> marker = {{Intrinsics("opencv5"), false},
                                     {RandomPose(rng, 0.05), true},
                                     {p_in_hand, false},
                                     {RandomPose(rng, 0.05), true}};
  std::vector<Block> dh_marker = marker;
  dh_marker.push_back({dh, false});
  const std::vector<Case> cases = {
      {"point", 2,
       [&](const NoiseModel& n) {
         return MakePointProjectionFactor("opencv5", z.row(0).transpose(), n, p.row(0).transpose());
       },
       camera},
      {"board", 2, [&](const NoiseModel& n) { return MakeBoardFactor("opencv5", z, n, p); },
       camera},
      {"marker", 2,
       [&](const NoiseModel& n) {
         return MakeKnownKinematicsMarkerFactor("opencv5", {300, 200}, n, base_from_chain);
       },
       marker},
      {"dh_marker", 2,
       [&](const NoiseModel& n) {
         return MakeDHMarkerFactor("opencv5", {300, 200}, n, q, base_from_chain, identity);
       },
       dh_marker},
      {"gravity",
       3,
       [&](const NoiseModel& n) {
         return MakeGravityFactor("scale_bias", {0.1, -0.2, 9.7}, n, {0, 0, -9.81});
       },
       {{RandomPose(rng), true}, {RandomPose(rng), true}, {accel, false}}},
      {"disparity",
       1,
       [&](const NoiseModel& n) {
         return MakeDisparityFactor(800.0, n, {0.3, 0.4, 0.0});
       },
       {{world_from_rig, true}, {cam_from_rig, true}, {ab, false}}},
  };
  std::normal_distribution<double> g;
  for (const Case& c : cases) {
    // A random SPD Σ and a diagonal one.
    Eigen::MatrixXd A(c.dim, c.dim);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
    const Eigen::MatrixXd S = A * A.transpose() + 0.5 * Eigen::MatrixXd::Identity(c.dim, c.dim);
    Eigen::VectorXd sig(c.dim);
    for (int i = 0; i < c.dim; ++i) sig[i] = 0.5 + i;
    const Eigen::MatrixXd D = sig.array().square().matrix().asDiagonal();
    const Eigen::MatrixXd L = S.llt().matrixL();
    const Eigen::VectorXd e = Eval(*c.make(NoiseModel::Unit(c.dim)), c.blocks);
    double full = 0, diag = 0;
    for (Eigen::Index k = 0; k < e.size(); k += c.dim) {
      const Eigen::VectorXd ek = e.segment(k, c.dim);
      full += ek.dot(S.ldlt().solve(ek));
      diag += ek.dot(D.ldlt().solve(ek));
    }
    const auto cost = [&](const NoiseModel& n) { return Eval(*c.make(n), c.blocks).squaredNorm(); };
    EXPECT_NEAR(cost(NoiseModel::Covariance(S)), full, 1e-9 * full) << c.name;
    EXPECT_NEAR(cost(NoiseModel::Information(S.inverse())), full, 1e-9 * full) << c.name;
    EXPECT_NEAR(cost(NoiseModel::SqrtInformation(L.inverse())), full, 1e-9 * full) << c.name;
    EXPECT_NEAR(cost(NoiseModel::Sigmas(sig)), diag, 1e-9 * diag) << c.name;
    EXPECT_NEAR(cost(NoiseModel::Covariance(D)), diag, 1e-9 * diag) << c.name;
    EXPECT_NEAR(cost(NoiseModel::Information(D.inverse())), diag, 1e-9 * diag) << c.name;
    // Jacobians are whitened too.
    ExpectJacobiansMatch(*c.make(NoiseModel::Covariance(S)), c.blocks);
    // A noise of the wrong dimension is refused when the factor is built.
    EXPECT_THROW(c.make(NoiseModel::Unit(c.dim + 1)), Error) << c.name;
  }
}

}  // namespace
}  // namespace boxplus

namespace boxplus {
namespace {

// The Δ-error templates are instantiated for the error conventions only:
// SE-Sync's chordal residual is its own kind, refused at compile time (no
// run-time check inside the autodiff functors) and skipped by the run-time
// dispatch.
template <class C, class = void>
struct HasRelativePoseError : std::false_type {};
template <class C>
struct HasRelativePoseError<C, std::void_t<decltype(RelativePose3DError<C>(
                                   std::declval<const double*>(), std::declval<const double*>(),
                                   std::declval<const double*>(), std::declval<double*>()))>>
    : std::true_type {};

TEST(RelativePoseError, RejectsTheSESyncConvention) {
  static_assert(HasRelativePoseError<pose_error::G2o>::value);
  static_assert(HasRelativePoseError<pose_error::Log>::value);
  static_assert(HasRelativePoseError<pose_error::Compound>::value);
  static_assert(!HasRelativePoseError<ChordalPrecisions>::value);
  bool called = false;
  EXPECT_FALSE(WithErrorConvention(PoseErrorConvention::kSESync, [&](auto) { called = true; }));
  EXPECT_FALSE(called);
  EXPECT_TRUE(WithErrorConvention(PoseErrorConvention::kG2o, [&](auto) { called = true; }));
  EXPECT_TRUE(called);
  const double x3[7] = {0, 0, 0, 0, 0, 0, 1}, z3[7] = {1, 0, 0, 0, 0, 0, 1};
  double e3[6];
  RelativePose3DError<pose_error::G2o>(x3, x3, z3, e3);
  EXPECT_DOUBLE_EQ(e3[0], -1.0);
}

// The compound convention is the manifold's ⊟ of x_ij = xᵢ⁻¹xⱼ and z: in 2D
// [t_ij − t_z, wrap(θ_ij − θ_z)], the translation not rotated into z's frame
// (g2o's is R_zᵀ(t_ij − t_z)); in 3D SE3Ops::Minus of SE3 values.
TEST(RelativePoseError, CompoundIsTheManifoldMinus) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const SE2 A(Eigen::Vector2d(u(rng), u(rng)), u(rng)),
        B(Eigen::Vector2d(u(rng), u(rng)), u(rng));
    const Eigen::Vector3d z(u(rng), u(rng), u(rng));
    double e[3], g[3];
    RelativePose2DError<pose_error::Compound>(A.ambient().data(), B.ambient().data(), z.data(), e);
    RelativePose2DError<pose_error::G2o>(A.ambient().data(), B.ambient().data(), z.data(), g);
    const SE2 AB = A.inverse() * B;
    const Eigen::Vector2d t = AB.ambient().head<2>() - z.head<2>();
    EXPECT_NEAR(e[0], t.x(), 1e-12);
    EXPECT_NEAR(e[1], t.y(), 1e-12);
    EXPECT_NEAR(e[2], g[2], 0.0);
    const Eigen::Vector2d tg = Eigen::Rotation2Dd(-z[2]) * t;
    EXPECT_NEAR(g[0], tg.x(), 1e-12);
    EXPECT_NEAR(g[1], tg.y(), 1e-12);
    const Pose a = RandomPose(rng, 2.0), b = RandomPose(rng, 2.0), zp = RandomPose(rng, 2.0);
    double e3[6], m3[6];
    RelativePose3DError<pose_error::Compound>(a.data(), b.data(), zp.data(), e3);
    const SE3 ab = SE3::FromAmbient(a.data()).inverse() * SE3::FromAmbient(b.data());
    SE3Ops::Minus(ab.ambient().data(), zp.data(), m3);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(e3[k], m3[k], 1e-12);
  }
}

// MakePrior finds each built-in manifold in its table and refuses the others.
TEST(Prior, EveryBuiltInManifoldByTable) {
  for (const char* kind : {"Rn", "SO2", "SO3", "SE2", "SE3", "S2"}) {
    const auto m = MakeManifold(kind, 4);
    Eigen::VectorXd z(m->AmbientSize());
    z.setZero();
    z[z.size() - 1] = 1.0;  // the identity / north pole of each ambient layout
    const auto f = MakePrior(*m, z, NoiseModel::Unit(m->TangentSize()), kind);
    EXPECT_EQ(f->num_residuals(), m->TangentSize()) << kind;
    Eigen::VectorXd r(f->num_residuals());
    const double* x[] = {z.data()};
    ASSERT_TRUE(f->Evaluate(x, r.data(), nullptr)) << kind;
    EXPECT_LT(r.norm(), 1e-12) << kind;  // x = z
  }
  const auto product =
      std::make_shared<ProductManifold>(std::vector<std::shared_ptr<const ceres::Manifold>>{
          MakeManifold("SO3"), MakeManifold("Rn", 3)});
  Eigen::VectorXd z = Eigen::VectorXd::Zero(product->AmbientSize());
  EXPECT_THROW(MakePrior(*product, z, NoiseModel::Unit(product->TangentSize()), "p"), Error);
  EXPECT_THROW(
      MakePrior(*MakeManifold("SO3"), Eigen::Vector4d(0, 0, 0, 1), NoiseModel::Unit(2), "p"),
      Error);
}

// A prior on some coordinates of an Rⁿ: r = W (x[idx] − z), the Jacobian W in
// the chosen columns and zero elsewhere (a linear factor: exact, no tolerance);
// bad selections are refused.
TEST(Prior, OnSomeCoordinatesOfRn) {
  const auto rn = MakeManifold("Rn", 5);
  Eigen::Matrix2d S;
  S << 4, 1, 1, 3;
  const NoiseModel noise = NoiseModel::Covariance(S);
  const std::vector<int> idx = {3, 1};
  const auto f = MakeCoordinatePrior(*rn, idx, Eigen::Vector2d(0.5, -1), noise, "p");
  ASSERT_EQ(f->num_residuals(), 2);
  Eigen::VectorXd x(5);
  x << 1, 2, 3, 4, 5;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 5, Eigen::RowMajor> J;
  const double* xs[] = {x.data()};
  double* js[] = {J.data()};
  ASSERT_TRUE(f->Evaluate(xs, r.data(), js));
  const Eigen::Matrix2d W = noise.sqrt_information();
  EXPECT_LT((r - W * Eigen::Vector2d(4 - 0.5, 2 + 1)).norm(), 1e-12);
  Eigen::Matrix<double, 2, 5> expected = Eigen::Matrix<double, 2, 5>::Zero();
  expected.col(3) = W.col(0);
  expected.col(1) = W.col(1);
  EXPECT_TRUE(J == expected);
  const NoiseModel unit = NoiseModel::Unit(2);
  EXPECT_THROW(MakeCoordinatePrior(*rn, {1, 1}, Eigen::Vector2d::Zero(), unit, "p"), Error);
  EXPECT_THROW(MakeCoordinatePrior(*rn, {0, 5}, Eigen::Vector2d::Zero(), unit, "p"), Error);
  EXPECT_THROW(MakeCoordinatePrior(*rn, {0}, Eigen::Vector2d::Zero(), unit, "p"), Error);
  EXPECT_THROW(
      MakeCoordinatePrior(*MakeManifold("SO3"), {0, 1}, Eigen::Vector2d::Zero(), unit, "p"), Error);
}

// W alone is stored; un-whitening solves with it in every shape of W and
// agrees with the explicit inverse.
TEST(NoiseModel, UnwhitenSolvesWithW) {
  Eigen::Matrix3d S;
  S << 4, 1, 0.5, 1, 3, 0.2, 0.5, 0.2, 2;
  Eigen::Matrix3d G;
  G << 2, 1, 0, -1, 3, 1, 0.5, 0, 1;  // neither triangular nor diagonal
  const std::vector<NoiseModel> models = {
      NoiseModel::Unit(3),
      NoiseModel::Sigmas(Eigen::Vector3d(0.5, 2, 3)),
      NoiseModel::Covariance(S),
      NoiseModel::Information(S),
      NoiseModel::SqrtInformation(G),
      NoiseModel::DiagonalSqrtInformation(Eigen::Vector3d(2, 0.5, 4))};
  Eigen::VectorXd r(6);
  r << 0.3, -1.2, 2.0, 0.7, 0.1, -0.4;
  for (const NoiseModel& n : models) {
    const Eigen::MatrixXd W = n.sqrt_information();
    const Eigen::MatrixXd W_inv = W.inverse();
    EXPECT_LT((n.inverse_sqrt_information() - W_inv).norm(), 1e-12) << n.Describe();
    EXPECT_LT((n.covariance() - W_inv * W_inv.transpose()).norm(), 1e-12) << n.Describe();
    Eigen::VectorXd e(6);
    e << W_inv * r.head<3>(), W_inv * r.tail<3>();
    EXPECT_LT((n.Unwhiten(r) - e).norm(), 1e-12) << n.Describe();
    EXPECT_LT((n.Whiten(n.Unwhiten(r)) - r).norm(), 1e-12) << n.Describe();
  }
  EXPECT_LT((NoiseModel::Covariance(S).covariance() - S).norm(), 1e-12);
  EXPECT_LT(
      (NoiseModel::Sigmas(Eigen::Vector3d(0.5, 2, 3)).sigmas() - Eigen::Vector3d(0.5, 2, 3)).norm(),
      1e-15);
  EXPECT_THROW(NoiseModel::DiagonalSqrtInformation(Eigen::Vector2d(1, 0)), Error);
  EXPECT_THROW(NoiseModel::DiagonalSqrtInformation(Eigen::Vector2d(1, NAN)), Error);
  EXPECT_THROW(NoiseModel::Unit(3).Unwhiten(Eigen::VectorXd::Ones(4)), Error);
}

}  // namespace
}  // namespace boxplus
