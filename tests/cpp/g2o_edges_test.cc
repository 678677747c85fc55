// The factors of g2o's offset, prior and point edges (factors/pose/
// offset_pose.h, point_in_frame.h): autodiff Jacobians mapped to the tangent
// by ⊞'s Jacobian against central differences through ⊞, at random points; and
// exact values against homogeneous matrices (g2o's isometries).
#include <cmath>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "boxplus/factors/pose/offset_pose.h"
#include "boxplus/factors/pose/point_in_frame.h"
#include "boxplus/manifolds.h"
#include "boxplus/noise.h"

namespace boxplus {
namespace {

using Vec = Eigen::VectorXd;

struct Block {
  Vec x;
  std::shared_ptr<const ceres::Manifold> manifold;
};

Vec Eval(const ceres::CostFunction& cost, const std::vector<Block>& blocks) {
  std::vector<const double*> ptrs;
  for (const auto& b : blocks) ptrs.push_back(b.x.data());
  Vec r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(ptrs.data(), r.data(), nullptr));
  return r;
}

void ExpectJacobiansMatch(const ceres::CostFunction& cost, const std::vector<Block>& blocks) {
  const int m = cost.num_residuals();
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<const double*> ptrs;
  std::vector<RowMajor> J;
  for (const auto& b : blocks) {
    ptrs.push_back(b.x.data());
    J.emplace_back(m, b.x.size());
  }
  std::vector<double*> jptrs;
  for (auto& j : J) jptrs.push_back(j.data());
  Vec r(m);
  ASSERT_TRUE(cost.Evaluate(ptrs.data(), r.data(), jptrs.data()));
  for (size_t k = 0; k < blocks.size(); ++k) {
    const ceres::Manifold& M = *blocks[k].manifold;
    const int n = M.TangentSize();
    RowMajor P(M.AmbientSize(), n);
    M.PlusJacobian(blocks[k].x.data(), P.data());
    const Eigen::MatrixXd Jt = J[k] * P;
    for (int j = 0; j < n; ++j) {
      const double h = 1e-6;
      Vec rs[2];
      for (int s = 0; s < 2; ++s) {
        std::vector<Block> moved = blocks;
        Vec d = Vec::Zero(n);
        d[j] = s == 0 ? h : -h;
        M.Plus(blocks[k].x.data(), d.data(), moved[k].x.data());
        rs[s] = Eval(cost, moved);
      }
      const Vec numeric = (rs[0] - rs[1]) / (2 * h);
      const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
      EXPECT_LT((Jt.col(j) - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale)
          << "block " << k << " direction " << j;
    }
  }
}

Vec RandomSE2(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Vector3d(g(rng), g(rng), 2.0 * g(rng));
}

Vec RandomSE3(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Vector4d q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  Vec x(7);
  x << g(rng), g(rng), g(rng), q;
  return x;
}

Eigen::Matrix3d H2(const Vec& x) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(x[2]).toRotationMatrix();
  M.topRightCorner<2, 1>() = x.head<2>();
  return M;
}

Eigen::Matrix4d H3(const Vec& x) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = Eigen::Quaterniond(x[6], x[3], x[4], x[5]).toRotationMatrix();
  M.topRightCorner<3, 1>() = x.head<3>();
  return M;
}

// A random SPD information of size n, and its noise model.
NoiseModel RandomNoise(std::mt19937& rng, int n) {
  std::normal_distribution<double> g;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
  return NoiseModel::Information(A * A.transpose() + n * Eigen::MatrixXd::Identity(n, n));
}

const auto kSE2 = MakeManifold("SE2");
const auto kSE3 = MakeManifold("SE3");

TEST(G2oEdges, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec a2 = RandomSE2(rng), b2 = RandomSE2(rng), o2 = RandomSE2(rng), p2 = RandomSE2(rng);
    const Vec a3 = RandomSE3(rng), b3 = RandomSE3(rng), o3 = RandomSE3(rng), p3 = RandomSE3(rng);
    const Vec l2 = RandomSE2(rng).head<2>(), l3 = RandomSE3(rng).head<3>();
    const auto r2 = MakeManifold("Rn", 2), r3 = MakeManifold("Rn", 3);
    ExpectJacobiansMatch(*MakeOffsetPose2D(RandomSE2(rng), o2, p2, RandomNoise(rng, 3)),
                         {{a2, kSE2}, {b2, kSE2}});
    ExpectJacobiansMatch(*MakeOffsetPose3D(RandomSE3(rng), o3, p3, RandomNoise(rng, 6)),
                         {{a3, kSE3}, {b3, kSE3}});
    ExpectJacobiansMatch(*MakeOffsetPosePrior2D(RandomSE2(rng), o2, RandomNoise(rng, 3)),
                         {{b2, kSE2}});
    ExpectJacobiansMatch(*MakeOffsetPosePrior3D(RandomSE3(rng), o3, RandomNoise(rng, 6)),
                         {{b3, kSE3}});
    ExpectJacobiansMatch(*MakePointInPose2D(l2, o2, RandomNoise(rng, 2)), {{a2, kSE2}, {l2, r2}});
    ExpectJacobiansMatch(*MakePointInPose3D(l3, o3, RandomNoise(rng, 3)), {{a3, kSE3}, {l3, r3}});
    ExpectJacobiansMatch(*MakePointDifference(l3, RandomNoise(rng, 3)), {{l3, r3}, {-l3, r3}});
    ExpectJacobiansMatch(*MakePositionPrior(l3, 7, RandomNoise(rng, 3)), {{a3, kSE3}});
    ExpectJacobiansMatch(*MakePositionPrior(l2, 2, RandomNoise(rng, 2)), {{l2, r2}});
    ExpectJacobiansMatch(*MakeBearing2D(0.3, RandomNoise(rng, 1)), {{a2, kSE2}, {l2 * 3, r2}});
  }
}

TEST(G2oEdges, ErrorsAreThoseOfHomogeneousMatrices) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec a = RandomSE3(rng), b = RandomSE3(rng), oa = RandomSE3(rng), ob = RandomSE3(rng),
              z = RandomSE3(rng);
    double e[6];
    OffsetPoseError<3>(a.data(), b.data(), oa.data(), ob.data(), z.data(), e);
    const Eigen::Matrix4d D = H3(z).inverse() * (H3(a) * H3(oa)).inverse() * H3(b) * H3(ob);
    Eigen::Quaterniond q(D.topLeftCorner<3, 3>());
    if (q.w() < 0) q.coeffs() *= -1;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(e[k], D(k, 3), 1e-12);
      EXPECT_NEAR(e[3 + k], q.coeffs()[k], 1e-12);
    }
    const Vec a2 = RandomSE2(rng), oa2 = RandomSE2(rng), l = RandomSE2(rng).head<2>(),
              zl = RandomSE2(rng).head<2>();
    double el[2];
    PointInPoseError<2>(a2.data(), l.data(), oa2.data(), zl.data(), el);
    const Eigen::Vector3d local = (H2(a2) * H2(oa2)).inverse() * Eigen::Vector3d(l[0], l[1], 1);
    EXPECT_NEAR(el[0], local[0] - zl[0], 1e-12);
    EXPECT_NEAR(el[1], local[1] - zl[1], 1e-12);
    // The 2D prior: wrap(θ) in [−π, π) of z⁻¹ · x.
    double ep[3];
    const Vec z2 = RandomSE2(rng);
    OffsetPoseError<2>(static_cast<const double*>(nullptr), a2.data(), nullptr,
                       Eigen::Vector3d::Zero().eval().data(), z2.data(), ep);
    const Eigen::Matrix3d P = H2(z2).inverse() * H2(a2);
    EXPECT_NEAR(ep[0], P(0, 2), 1e-12);
    EXPECT_NEAR(ep[1], P(1, 2), 1e-12);
    EXPECT_NEAR(ep[2], std::atan2(P(1, 0), P(0, 0)), 1e-12);
  }
}

TEST(G2oEdges, AMeasurementThatHoldsExactlyHasZeroError) {
  std::mt19937 rng(3);
  const Vec x = RandomSE3(rng), o = RandomSE3(rng);
  Vec xo(7);
  ComposePose<3, double>(x.data(), o.data(), xo.data());
  double e[6];
  OffsetPoseError<3>(static_cast<const double*>(nullptr), x.data(), nullptr, o.data(), xo.data(),
                     e);
  for (double v : e) EXPECT_NEAR(v, 0.0, 1e-15);
}

TEST(G2oEdges, BadMeasurementsAreRefusedByName) {
  const NoiseModel n3 = NoiseModel::Information(Eigen::Matrix3d::Identity());
  Eigen::Vector3d bad(1, NAN, 0);
  EXPECT_THROW(MakeOffsetPose2D(bad, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), n3), Error);
  EXPECT_THROW(MakePositionPrior(Eigen::Vector3d::Zero(), 3,
                                 NoiseModel::Information(Eigen::Matrix2d::Identity())),
               Error);  // a 3-vector with a 2×2 noise
  EXPECT_THROW(MakePositionPrior(Eigen::Vector3d::Zero(), 5, n3), Error);
}

}  // namespace
}  // namespace boxplus
