// Group identities and conversions of the value types (SO3, SE3, SO2, SE2, S2).
#include <random>

#include <gtest/gtest.h>

#include "boxplus/manifolds.h"

namespace boxplus {
namespace {

Eigen::Vector3d RandomVec(std::mt19937& rng, double scale) {
  std::normal_distribution<double> g(0, scale);
  return {g(rng), g(rng), g(rng)};
}

TEST(SO3, ExpLogRoundTripIncludingNearPi) {
  std::mt19937 rng(1);
  for (int k = 0; k < 500; ++k) {
    Eigen::Vector3d w = RandomVec(rng, 1.0);
    const double n = w.norm();
    if (k % 5 == 0) w *= (kPi - 1e-7) / n;  // just under π
    if (k % 5 == 1) w *= 1e-9 / n;          // tiny angle
    if (w.norm() >= kPi) continue;
    EXPECT_LT((SO3::Exp(w).Log() - w).norm(), 1e-9) << w.transpose();
    // exp(log R) = R as matrices
    const SO3 R = SO3::Exp(w);
    EXPECT_LT((SO3::Exp(R.Log()).matrix() - R.matrix()).norm(), 1e-12);
  }
}

TEST(SO3, QuaternionSignDoesNotChangeLog) {
  const SO3 a = SO3::Exp(Eigen::Vector3d(0.3, -2.0, 1.1));
  const SO3 b = SO3::FromQuaternion(-a.quat());
  EXPECT_LT((a.Log() - b.Log()).norm(), 1e-12);
  EXPECT_LT(a.boxminus(b).norm(), 1e-12);
}

TEST(SO3, LogAtPiDependsOnTheRotationOnly) {
  // 180° about z as q and as −q (w = ±0): one rotation, one tangent vector.
  const SO3 a = SO3::FromQuaternion(Eigen::Vector4d(0, 0, 1, 0));
  const SO3 b = SO3::FromQuaternion(Eigen::Vector4d(-0.0, -0.0, -1, -0.0));
  EXPECT_LT((a.Log() - b.Log()).norm(), 1e-15);
  EXPECT_NEAR(a.Log().norm(), kPi, 1e-15);
  EXPECT_LT(
      (SO3().boxminus(a) - SO3::FromQuaternion(Eigen::Vector4d(0, 0, 0, -1)).boxminus(a)).norm(),
      1e-15);
}

TEST(SO3, GroupIdentities) {
  std::mt19937 rng(2);
  for (int k = 0; k < 200; ++k) {
    const SO3 a = SO3::Exp(RandomVec(rng, 1.5)), b = SO3::Exp(RandomVec(rng, 1.5));
    EXPECT_LT((a * a.inverse()).Log().norm(), 1e-12);
    EXPECT_LT(((a * b).matrix() - a.matrix() * b.matrix()).norm(), 1e-12);
    const Eigen::Vector3d p = RandomVec(rng, 3.0);
    EXPECT_LT((a * p - a.matrix() * p).norm(), 1e-12);
    EXPECT_LT((SO3::FromMatrix(a.matrix()).matrix() - a.matrix()).norm(), 1e-12);
  }
}

TEST(SO3, RenormalisesAfterManySteps) {
  SO3 x;
  std::mt19937 rng(3);
  for (int k = 0; k < 100000; ++k) x = x.boxplus(RandomVec(rng, 0.1));
  EXPECT_NEAR(x.quat().norm(), 1.0, 1e-14);
}

TEST(SO3, RejectsBadInput) {
  EXPECT_THROW(SO3::FromQuaternion(Eigen::Vector4d::Zero()), Error);
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M(0, 0) = -1;  // a reflection
  EXPECT_THROW(SO3::FromMatrix(M), Error);
  M = Eigen::Matrix3d::Identity() * 2;
  EXPECT_THROW(SO3::FromMatrix(M), Error);
}

TEST(SE3, TransformAndLocalCoordinates) {
  std::mt19937 rng(4);
  for (int k = 0; k < 200; ++k) {
    const SE3 a(SO3::Exp(RandomVec(rng, 1.0)), RandomVec(rng, 5.0));
    const SE3 b(SO3::Exp(RandomVec(rng, 1.0)), RandomVec(rng, 5.0));
    const Eigen::Vector3d p = RandomVec(rng, 5.0);
    EXPECT_LT((a.tolocal(a.fromlocal(p)) - p).norm(), 1e-11);
    EXPECT_LT(((a.transform() * p.homogeneous()).head<3>() - a.fromlocal(p)).norm(), 1e-11);
    EXPECT_LT(((a * b).transform() - a.transform() * b.transform()).norm(), 1e-11);
    EXPECT_LT(((a * a.inverse()).transform() - Eigen::Matrix4d::Identity()).norm(), 1e-11);
    EXPECT_LT((SE3::FromMatrix(a.transform()).transform() - a.transform()).norm(), 1e-11);
  }
}

TEST(SE3, ExpLogRoundTrip) {
  Eigen::Matrix<double, 6, 1> d;
  d << 1, -2, 3, 0.3, -0.2, 2.9;
  EXPECT_LT((SE3::Exp(d).Log() - d).norm(), 1e-12);
  Eigen::Vector3d e(4, 5, -3.0);
  EXPECT_LT((SE2::Exp(e).Log() - e).norm(), 1e-12);
}

TEST(SE3, BoxplusIsCompoundWithTranslationFirst) {
  const SE3 x(SO3::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(1, 2, 3));
  Eigen::Matrix<double, 6, 1> d;
  d << 0.5, -0.5, 1.0, 0.0, 0.0, 0.2;
  const SE3 y = x.boxplus(d);
  EXPECT_LT((y.pos() - Eigen::Vector3d(1.5, 1.5, 4.0)).norm(), 1e-15);
  const Eigen::Matrix3d expected =
      x.rotation().matrix() * SO3::Exp(Eigen::Vector3d(0, 0, 0.2)).matrix();
  EXPECT_LT((y.rotation().matrix() - expected).norm(), 1e-14);
}

TEST(SE2, GroupIdentitiesAndWrap) {
  const SE2 a(Eigen::Vector2d(1, 2), 3.0), b(Eigen::Vector2d(-1, 0.5), 2.0);
  EXPECT_LT(((a * b).transform() - a.transform() * b.transform()).norm(), 1e-12);
  EXPECT_LT(((a * a.inverse()).transform() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_GE((a * b).angle(), -kPi);
  EXPECT_LT((a * b).angle(), kPi);
  // Across the seam: 3.1 ⊟ −3.1 is a small positive step, not ≈ 2π.
  EXPECT_NEAR(SO2(-3.1).boxminus(SO2(3.1))[0], 2 * kPi - 6.2, 1e-12);
}

TEST(S2, TangentBasisIsOrthonormalAndOrthogonalToX) {
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k) {
    const S2 x(RandomVec(rng, 1.0));
    const auto B = x.tangent_basis();
    EXPECT_LT((B.transpose() * B - Eigen::Matrix2d::Identity()).norm(), 1e-12);
    EXPECT_LT((B.transpose() * x.vec()).norm(), 1e-12);
  }
  EXPECT_THROW(S2(Eigen::Vector3d::Zero()), Error);
}

}  // namespace
}  // namespace boxplus
