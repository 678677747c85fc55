// SE-Sync's certificate and the Riemannian staircase (certify/certificate.h,
// certify/staircase.h, certify/certify.h): the data matrix against the chordal
// residuals, the Stiefel manifold's ⊞ and Jacobians, certificates of known
// optima, and a ring whose winding local minimum the staircase escapes.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "../../cpp/src/certify/stiefel_manifold.h"
#include "boxplus/certify/certificate.h"
#include "boxplus/certify/certify.h"
#include "boxplus/io/g2o.h"
#include "boxplus/slam/load.h"
#include "boxplus/slam/pose_graph.h"

namespace boxplus::certify {
namespace {

using slam::InitMethod;
using slam::LoadOptions;
using slam::LoadPoseGraph;
using slam::PoseGraph;
using slam::PoseGraphOptions;

const std::string kData = std::string(BOXPLUS_SOURCE_DIR) + "/tests/data/";

// A ring of n poses on a circle (radius 5, heading along it), exact
// relative-pose edges between neighbours (and the closing one); 2D or 3D.
io::Graph Ring(int d, int n, double noise = 0.0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  io::Graph g;
  g.dimension = d;
  std::vector<Eigen::Isometry3d> T(n);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    T[i] = Eigen::Translation3d(5 * std::cos(a), 5 * std::sin(a), 0.0) *
           Eigen::AngleAxisd(a + M_PI / 2, Eigen::Vector3d::UnitZ());
    io::Vertex v;
    v.id = i;
    v.kind = d == 2 ? io::VertexKind::kSE2 : io::VertexKind::kSE3;
    if (d == 2) {
      v.estimate = Eigen::Vector3d(T[i].translation().x(), T[i].translation().y(),
                                   std::remainder(a + M_PI / 2, 2 * M_PI));
    } else {
      Eigen::Quaterniond q(T[i].rotation());
      v.estimate.resize(7);
      v.estimate << T[i].translation(), q.x(), q.y(), q.z(), q.w();
    }
    g.AddVertex(v);
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Eigen::Isometry3d Z = T[i].inverse() * T[j];
    io::Edge e;
    e.from = i;
    e.to = j;
    if (d == 2) {
      const double th = std::atan2(Z.rotation()(1, 0), Z.rotation()(0, 0)) + noise * N(rng);
      e.kind = io::EdgeKind::kSE2;
      e.measurement = Eigen::Vector3d(Z.translation().x() + noise * N(rng),
                                      Z.translation().y() + noise * N(rng), th);
      e.information = Eigen::Matrix3d::Identity() * 10.0;
    } else {
      e.kind = io::EdgeKind::kSE3;
      Eigen::Quaterniond q(
          Z.rotation() *
          Eigen::AngleAxisd(noise * N(rng), Eigen::Vector3d::UnitX()).toRotationMatrix());
      e.measurement.resize(7);
      e.measurement << Z.translation() + noise * Eigen::Vector3d(N(rng), N(rng), N(rng)), q.x(),
          q.y(), q.z(), q.w();
      e.information = Eigen::Matrix<double, 6, 6>::Identity() * 10.0;
    }
    g.AddEdge(e);
  }
  return g;
}

TEST(Stiefel, PlusStaysOnTheManifoldAndItsJacobianIsTheDerivative) {
  std::mt19937 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int d : {2, 3}) {
    for (int r = d; r <= d + 2; ++r) {
      internal::StiefelManifold st(r, d);
      Eigen::MatrixXd A(r, d);
      for (int k = 0; k < A.size(); ++k) A.data()[k] = N(rng);
      const Eigen::MatrixXd Y = internal::OrthonormalFactor(A);
      const int T = st.TangentSize();
      Eigen::VectorXd delta(T);
      for (int k = 0; k < T; ++k) delta[k] = 0.3 * N(rng);
      Eigen::MatrixXd Z(r, d);
      ASSERT_TRUE(st.Plus(Y.data(), delta.data(), Z.data()));
      EXPECT_LT((Z.transpose() * Z - Eigen::MatrixXd::Identity(d, d)).norm(), 1e-12);
      // x ⊞ 0 = x
      Eigen::VectorXd zero = Eigen::VectorXd::Zero(T);
      ASSERT_TRUE(st.Plus(Y.data(), zero.data(), Z.data()));
      EXPECT_LT((Z - Y).norm(), 1e-14);
      // PlusJacobian = ∂(Y ⊞ δ)/∂δ at 0 (central differences).
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(r * d, T);
      ASSERT_TRUE(st.PlusJacobian(Y.data(), J.data()));
      const double h = 1e-6;
      for (int k = 0; k < T; ++k) {
        Eigen::VectorXd dp = zero, dm = zero;
        dp[k] = h;
        dm[k] = -h;
        Eigen::MatrixXd Zp(r, d), Zm(r, d);
        st.Plus(Y.data(), dp.data(), Zp.data());
        st.Plus(Y.data(), dm.data(), Zm.data());
        const Eigen::MatrixXd fd = (Zp - Zm) / (2 * h);
        EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(fd.data(), r * d) - J.col(k)).norm(), 1e-8)
            << "d " << d << " r " << r << " k " << k;
      }
      // (x ⊞ δ) ⊟ x = δ to first order; MinusJacobian · PlusJacobian = I.
      Eigen::VectorXd small = 1e-6 * delta, back(T);
      ASSERT_TRUE(st.Plus(Y.data(), small.data(), Z.data()));
      ASSERT_TRUE(st.Minus(Z.data(), Y.data(), back.data()));
      EXPECT_LT((back - small).norm(), 1e-11);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Jm(T, r * d);
      ASSERT_TRUE(st.MinusJacobian(Y.data(), Jm.data()));
      EXPECT_LT((Jm * J - Eigen::MatrixXd::Identity(T, T)).norm(), 1e-12);
    }
  }
}

TEST(Certificate, DataMatrixGivesSESyncObjective) {
  for (int d : {2, 3}) {
    io::Graph g = Ring(d, 7, 0.2, 5);
    // Move the estimates off the measurements.
    std::mt19937 rng(9);
    std::normal_distribution<double> N(0.0, 0.3);
    for (io::Vertex& v : g.vertices) {
      for (int k = 0; k < d; ++k) v.estimate[k] += N(rng);
    }
    PoseGraphOptions po;
    po.convention = PoseErrorConvention::kSESync;
    PoseGraph pg(g, po);
    const SESyncGraph sg = SESyncGraph::FromGraph(g);
    const double f = SESyncObjective(sg.DataMatrix(), sg.Stack(g));
    EXPECT_NEAR(f, pg.Chi2(), 1e-10 * pg.Chi2()) << "d = " << d;
  }
}

TEST(Certificate, CertifiesTheOptimumOfSmallGrid3D) {
  LoadOptions lo;
  lo.graph.convention = PoseErrorConvention::kSESync;
  lo.init = InitMethod::kChordal;
  for (const char* file : {"tinyGrid3D.g2o", "smallGrid3D.g2o", "MIT.g2o", "CSAIL.g2o"}) {
    auto pg = LoadPoseGraph(kData + file, lo);
    pg->Solve(CertifyLocalSolverOptions());
    const CertifyResult r = CertifyPoseGraph(pg.get());
    EXPECT_TRUE(r.certified) << file << ": " << r.message;
    EXPECT_FALSE(r.staircase_used) << file;
    EXPECT_NEAR(r.objective, pg->Chi2(), 1e-9 * r.objective) << file;
    EXPECT_LE(r.suboptimality_bound, 1e-6 * r.objective) << file;
  }
}

TEST(Certificate, RingWindingIsNotCertifiedAndTheStaircaseEscapesIt) {
  for (int d : {2, 3}) {
    const int n = 10;
    io::Graph g = Ring(d, n, 0.01, 11);
    // Start from rotations wound once more around the ring (θᵢ + 2πi/n):
    // each edge's rotation error is 36°, a local minimum of the rotations.
    for (int i = 0; i < n; ++i) {
      io::Vertex& v = g.vertices[i];
      const double extra = 2 * M_PI * i / n;
      if (d == 2) {
        v.estimate[2] = std::remainder(v.estimate[2] + extra, 2 * M_PI);
      } else {
        Eigen::Quaterniond q(v.estimate[6], v.estimate[3], v.estimate[4], v.estimate[5]);
        q = Eigen::AngleAxisd(extra, Eigen::Vector3d::UnitZ()) * q;
        v.estimate.tail<4>() << q.x(), q.y(), q.z(), q.w();
      }
    }
    PoseGraphOptions po;
    po.convention = PoseErrorConvention::kSESync;
    PoseGraph pg(g, po);
    pg.Solve(CertifyLocalSolverOptions());
    const double local = pg.Chi2();

    CertifyOptions verify_only;
    verify_only.max_rank = d;
    const CertifyResult stuck = CertifyPoseGraph(&pg, verify_only);
    EXPECT_FALSE(stuck.certified) << "d = " << d << ": " << stuck.message;
    EXPECT_LT(stuck.certificate.lambda_min, 0.0) << "d = " << d;

    const CertifyResult freed = CertifyPoseGraph(&pg);
    EXPECT_TRUE(freed.certified) << "d = " << d << ": " << freed.message;
    EXPECT_TRUE(freed.staircase_used);
    EXPECT_GT(freed.max_rank_reached, d);
    EXPECT_LT(freed.objective, 0.1 * local) << "d = " << d;
    EXPECT_NEAR(pg.Chi2(), freed.objective, 1e-9 * local);
    // The gauge pose keeps its estimate.
    EXPECT_LT((pg.graph().vertices[0].estimate - g.vertices[0].estimate).norm(), 1e-12);
  }
}

TEST(Certificate, RefusesWhatItDoesNotCover) {
  auto pg = LoadPoseGraph(kData + "landmarks2d.g2o");
  EXPECT_THROW(CertifyPoseGraph(pg.get()), Error);
  io::Graph two = Ring(2, 5);
  io::Graph g = two;
  // Two components: no common gauge.
  for (int i = 0; i < 5; ++i) {
    io::Vertex v = two.vertices[i];
    v.id += 100;
    g.AddVertex(v);
  }
  EXPECT_THROW(SESyncGraph::FromGraph(g), Error);
}

}  // namespace
}  // namespace boxplus::certify
