// Tests of the SLAM factors (analytic Jacobians against autodiff, the log
// convention against the SE(3) exponential), the pose graph and the
// initialisations.
#include <algorithm>
#include <random>

#include <ceres/cost_function.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "boxplus/factors/pose/bearing_range.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/factors/pose/observed_point.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/loss.h"
#include "boxplus/manifolds.h"
#include "boxplus/slam/initialization.h"
#include "boxplus/slam/pose_graph.h"

namespace boxplus {
namespace {

const std::string kData = std::string(BOXPLUS_SOURCE_DIR) + "/tests/data/";

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Residual and tangent-space Jacobians (ambient Jacobian × PlusJacobian).
void Evaluate(const ceres::CostFunction& f, const std::vector<const double*>& x,
              const std::vector<const ceres::Manifold*>& m, Eigen::VectorXd* r,
              std::vector<RowMat>* J) {
  const int n = f.num_residuals();
  r->resize(n);
  std::vector<RowMat> Ja;
  std::vector<double*> ptrs;
  for (size_t k = 0; k < x.size(); ++k) {
    Ja.emplace_back(n, f.parameter_block_sizes()[k]);
  }
  for (auto& j : Ja) ptrs.push_back(j.data());
  ASSERT_TRUE(f.Evaluate(x.data(), r->data(), ptrs.data()));
  J->clear();
  for (size_t k = 0; k < x.size(); ++k) {
    RowMat P(m[k]->AmbientSize(), m[k]->TangentSize());
    m[k]->PlusJacobian(x[k], P.data());
    J->push_back(Ja[k] * P);
  }
}

Eigen::Matrix<double, 7, 1> RandomSE3(std::mt19937& rng, double rot_scale = 3.0) {
  std::normal_distribution<double> g(0, 1);
  Eigen::Vector3d w(g(rng), g(rng), g(rng));
  w = w.normalized() * std::uniform_real_distribution<double>(0, rot_scale)(rng);
  Eigen::Matrix<double, 7, 1> x;
  x << 3 * g(rng), 3 * g(rng), 3 * g(rng), SO3::Exp(w).ambient();
  return x;
}

Eigen::Matrix<double, 6, 6> RandomInfo(std::mt19937& rng, int n = 6) {
  std::normal_distribution<double> g(0, 1);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n * n; ++i) A.data()[i] = g(rng);
  Eigen::MatrixXd I = A * A.transpose() + Eigen::MatrixXd::Identity(n, n);
  Eigen::Matrix<double, 6, 6> out = Eigen::Matrix<double, 6, 6>::Identity();
  out.topLeftCorner(n, n) = I;
  return out;
}

void ExpectAnalyticMatchesAutodiff3D(const Eigen::Matrix<double, 7, 1>& xi,
                                     const Eigen::Matrix<double, 7, 1>& xj,
                                     const Eigen::Matrix<double, 7, 1>& z,
                                     const Eigen::Matrix<double, 6, 6>& info,
                                     PoseErrorConvention convention, int trial) {
  static const auto se3 = MakeManifold("SE3");
  const NoiseModel noise = NoiseModel::Information(info);
  auto analytic = MakeRelativePose3D(z, noise, convention);
  auto autodiff = MakeRelativePose3DAutoDiff(z, noise, convention);
  Eigen::VectorXd ra, rb;
  std::vector<RowMat> Ja, Jb;
  Evaluate(*analytic, {xi.data(), xj.data()}, {se3.get(), se3.get()}, &ra, &Ja);
  Evaluate(*autodiff, {xi.data(), xj.data()}, {se3.get(), se3.get()}, &rb, &Jb);
  EXPECT_LT((ra - rb).norm(), 1e-10 * (1 + ra.norm())) << "trial " << trial;
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT((Ja[k] - Jb[k]).norm(), 1e-9 * (1 + Jb[k].norm())) << "trial " << trial;
  }
}

TEST(RelativePose3D, AnalyticJacobiansMatchAutodiff) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const auto xi = RandomSE3(rng), xj = RandomSE3(rng);
    // Measurements near the truth and far from it (w of q_Δ near 0 included).
    const auto z = trial % 2 ? RandomSE3(rng) : RandomSE3(rng, 0.1);
    const auto info = RandomInfo(rng);
    ExpectAnalyticMatchesAutodiff3D(xi, xj, z, info, PoseErrorConvention::kG2o, trial);
  }
}

// z = (x_i⁻¹ x_j) · exp of a rotation of angle ~scale (θ_Δ ~ scale).
Eigen::Matrix<double, 7, 1> NearRelative(const Eigen::Matrix<double, 7, 1>& xi,
                                         const Eigen::Matrix<double, 7, 1>& xj, double scale,
                                         std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  const Eigen::Quaterniond qi(xi[6], xi[3], xi[4], xi[5]), qj(xj[6], xj[3], xj[4], xj[5]);
  const Eigen::Vector3d w = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * scale;
  const Eigen::Quaterniond dq(Eigen::AngleAxisd(w.norm(), w.normalized()));
  const Eigen::Quaterniond qz = qi.conjugate() * qj * dq;
  Eigen::Matrix<double, 7, 1> z;
  z.head<3>() = qi.conjugate() * (xj.head<3>() - xi.head<3>()) +
                scale * Eigen::Vector3d(g(rng), g(rng), g(rng));
  z.tail<4>() = qz.coeffs();
  return z;
}

TEST(RelativePose3D, LogConventionAnalyticJacobiansMatchAutodiff) {
  std::mt19937 rng(5);
  // θ_Δ from 1e-5 (the series branch of c(θ)) over 1e-2 to arbitrary (up to π).
  const double scales[] = {1e-5, 3e-4, 5e-2, 0.5};
  for (int trial = 0; trial < 200; ++trial) {
    const auto xi = RandomSE3(rng), xj = RandomSE3(rng);
    const auto z = trial % 5 == 4 ? RandomSE3(rng) : NearRelative(xi, xj, scales[trial % 5], rng);
    const auto info = RandomInfo(rng);
    ExpectAnalyticMatchesAutodiff3D(xi, xj, z, info, PoseErrorConvention::kLog, trial);
  }
}

TEST(RelativePose2D, AnalyticJacobiansMatchAutodiff) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.14, 3.14);
  const auto se2 = MakeManifold("SE2");
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d xi(3 * u(rng), 3 * u(rng), u(rng)), xj(3 * u(rng), 3 * u(rng), u(rng)),
        z(u(rng), u(rng), u(rng));
    const Eigen::Matrix3d info = RandomInfo(rng, 3).topLeftCorner<3, 3>();
    Eigen::VectorXd ra, rb;
    std::vector<RowMat> Ja, Jb;
    Evaluate(*MakeRelativePose2D(z, NoiseModel::Information(info)), {xi.data(), xj.data()},
             {se2.get(), se2.get()}, &ra, &Ja);
    Evaluate(*MakeRelativePose2DAutoDiff(z, NoiseModel::Information(info)), {xi.data(), xj.data()},
             {se2.get(), se2.get()}, &rb, &Jb);
    EXPECT_LT((ra - rb).norm(), 1e-10 * (1 + ra.norm()));
    for (int k = 0; k < 2; ++k) EXPECT_LT((Ja[k] - Jb[k]).norm(), 1e-9 * (1 + Jb[k].norm()));
  }
}

// exp of SE(3) with tangent (u, ω): R = exp(ω), t = V(ω) u.
Eigen::Matrix<double, 7, 1> ExpSE3(const Eigen::Vector3d& u, const Eigen::Vector3d& w) {
  const double th = w.norm();
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  Eigen::Matrix3d V = Eigen::Matrix3d::Identity();
  if (th > 1e-12) {
    V += (1 - std::cos(th)) / (th * th) * W + (th - std::sin(th)) / (th * th * th) * W * W;
  }
  Eigen::Matrix<double, 7, 1> x;
  x << V * u, SO3::Exp(w).ambient();
  return x;
}

TEST(RelativePose3D, LogConventionInvertsTheSE3Exponential) {
  // With x_i = identity and z = identity, Δ = x_j: e must give back (u, ω).
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0, 1);
  const Eigen::Matrix<double, 7, 1> id = SE3().ambient();
  for (double scale : {1e-9, 1e-4, 0.3, 1.5, 3.0}) {
    const Eigen::Vector3d u(g(rng), g(rng), g(rng));
    Eigen::Vector3d w(g(rng), g(rng), g(rng));
    w = w.normalized() * scale;
    const auto xj = ExpSE3(u, w);
    double e[6];
    RelativePose3DError<pose_error::Log>(id.data(), xj.data(), id.data(), e);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(e[k], u[k], 1e-9) << scale;
      EXPECT_NEAR(e[3 + k], w[k], 1e-12) << scale;
    }
  }
}

TEST(RelativePose2D, LogConventionInvertsTheSE2Exponential) {
  for (double th : {1e-9, 1e-3, 0.5, 3.0, -2.0}) {
    const Eigen::Vector2d u(0.7, -1.3);
    // V(θ) = [[s, −(1−c)], [1−c, s]] / θ
    const double s = std::sin(th), c = std::cos(th);
    const Eigen::Vector2d t = std::abs(th) < 1e-8
                                  ? u
                                  : Eigen::Vector2d((s * u.x() - (1 - c) * u.y()) / th,
                                                    ((1 - c) * u.x() + s * u.y()) / th);
    const double xi[3] = {0, 0, 0}, xj[3] = {t.x(), t.y(), th}, z[3] = {0, 0, 0};
    double e[3];
    RelativePose2DError<pose_error::Log>(xi, xj, z, e);
    EXPECT_NEAR(e[0], u.x(), 1e-9);
    EXPECT_NEAR(e[1], u.y(), 1e-9);
    EXPECT_NEAR(e[2], th, 1e-12);
  }
}

TEST(LandmarkFactors, ZeroAtTheTruth) {
  const Eigen::Vector3d pose(1, 2, 0.5);
  const Eigen::Vector2d l(3, 4);
  const Eigen::Rotation2Dd R(0.5);
  const Eigen::Vector2d local = R.inverse() * (l - pose.head<2>());
  double e[2];
  ObservedPointError<2>(pose.data(), l.data(), local.data(), e);
  EXPECT_NEAR(Eigen::Vector2d(e[0], e[1]).norm(), 0, 1e-12);
  const double br[2] = {std::atan2(local.y(), local.x()), local.norm()};
  ASSERT_TRUE(BearingRange2DError(pose.data(), l.data(), br, e));
  EXPECT_NEAR(Eigen::Vector2d(e[0], e[1]).norm(), 0, 1e-12);
  const double on_pose[2] = {1, 2};
  EXPECT_FALSE(BearingRange2DError(pose.data(), on_pose, br, e));
}

// Reference optima from the peers (g2opy 2.3.0 and GTSAM 4.3.0 from the
// file's estimate, scored by harness.g2o_reference in numpy).
TEST(PoseGraph, TinyGrid3DReachesThePeersOptimum) {
  for (auto [conv, best] : {std::pair{PoseErrorConvention::kG2o, 6.727881617021661},
                            std::pair{PoseErrorConvention::kLog, 18.62781886709005}}) {
    slam::PoseGraphOptions o;
    o.convention = conv;
    slam::PoseGraph pg(io::ReadG2o(kData + "tinyGrid3D.g2o"), o);
    EXPECT_EQ(pg.gauge_vertex(), 0);
    EXPECT_TRUE(pg.problem().IsFixed(pg.variable(0)));
    const SolveSummary s = pg.Solve();
    EXPECT_TRUE(s.usable);
    EXPECT_LE(pg.Chi2(), best * (1 + 1e-6));
    EXPECT_NEAR(2 * s.final_cost, pg.Chi2(), 1e-9 * pg.Chi2());
  }
}

TEST(PoseGraph, LandmarksAndFixLines) {
  slam::PoseGraph pg(io::ReadG2o(kData + "landmarks2d.g2o"));
  EXPECT_EQ(pg.gauge_vertex(), 0);
  const SolveSummary s = pg.Solve();
  EXPECT_TRUE(s.usable);
  EXPECT_LT(pg.Chi2(), 1e-2);
  EXPECT_EQ(pg.problem().value(pg.variable(0))[0], 0.0);  // FIX 0 held
}

// Every convention's chi2 (EdgeChi2) is Σ‖r‖² of the factors the graph is
// built from, i.e. 2× the problem's cost, away from the optimum too.
TEST(PoseGraph, Chi2OfEveryConventionIsTheFactorsCost) {
  for (const char* file : {"tinyGrid3D.g2o", "landmarks2d.g2o"}) {
    for (auto conv : {PoseErrorConvention::kG2o, PoseErrorConvention::kLog,
                      PoseErrorConvention::kCompound, PoseErrorConvention::kSESync}) {
      slam::PoseGraphOptions o;
      o.convention = conv;
      slam::PoseGraph pg(io::ReadG2o(kData + file), o);
      const double chi2 = pg.Chi2();
      EXPECT_GT(chi2, 0.0) << file << " " << ToString(conv);
      EXPECT_NEAR(2 * pg.problem().Cost(), chi2, 1e-10 * chi2) << file << " " << ToString(conv);
    }
  }
}

// SE-Sync's edges register the model of their own residual: Error() is the
// chordal error [tⱼ − tᵢ − Rᵢt̃ᵢⱼ, vec(Rⱼ − RᵢR̃ᵢⱼ)], not the whitened residual.
TEST(PoseGraph, ChordalEdgesUnwhitenToTheChordalError) {
  slam::PoseGraphOptions o;
  o.convention = PoseErrorConvention::kSESync;
  slam::PoseGraph pg(io::ReadG2o(kData + "tinyGrid3D.g2o"), o);
  const io::Edge& e = pg.graph().edges[0];
  Problem& p = pg.problem();
  ASSERT_EQ(p.noise(0).dim(), 12);
  const SE3 A = SE3::FromAmbient(p.value(pg.variable(e.from)));
  const SE3 B = SE3::FromAmbient(p.value(pg.variable(e.to)));
  const SE3 Z = SE3::FromAmbient(e.measurement.data());
  Eigen::VectorXd expected(12);
  expected.head<3>() = B.pos() - A.pos() - A.rotation().matrix() * Z.pos();
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> D =
      B.rotation().matrix() - A.rotation().matrix() * Z.rotation().matrix();
  expected.tail<9>() = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(D.data());
  EXPECT_LT((p.Error(0) - expected).norm(), 1e-12 * (1 + expected.norm()));
  const ChordalPrecisions c = ChordalPrecisionsOf(NoiseModel::Information(e.information));
  EXPECT_NEAR(p.Residual(0).head<3>().norm(), std::sqrt(c.tau) * expected.head<3>().norm(), 1e-12);
}

// The edges of the file are named by the graph ("edge i-j") without a string
// each; an edge added after a measurement of the caller's keeps its own name.
TEST(PoseGraph, EdgeNamesAreDerived) {
  slam::PoseGraph pg(io::ReadG2o(kData + "landmarks2d.g2o"));
  Problem& p = pg.problem();
  const int n = p.num_measurements();
  ASSERT_GT(n, 1);
  for (int k = 0; k < n; ++k) {
    const io::Edge& e = pg.graph().edges[k];
    EXPECT_EQ(p.measurement_name(k), "edge " + std::to_string(e.from) + "-" + std::to_string(e.to));
  }
  io::Edge extra = pg.graph().edges[0];
  pg.AddEdge(extra);  // still in step with the graph: derived
  EXPECT_EQ(p.measurement_name(n), p.measurement_name(0));
  const int x = pg.variable(extra.from);
  const Eigen::VectorXd z = Eigen::Map<const Eigen::VectorXd>(p.value(x), 3);
  p.AddMeasurement(MakePrior(p.manifold(x), z, NoiseModel::Unit(3), "prior"), {x},
                   NoiseModel::Unit(3));
  EXPECT_EQ(p.measurement_name(n + 1), "z" + std::to_string(n + 1));
  pg.AddEdge(extra);
  EXPECT_EQ(p.measurement_name(n + 2), p.measurement_name(0));
  EXPECT_EQ(p.measurement_name(n + 1), "z" + std::to_string(n + 1));
}

// A chain of n SE(2) poses with an edge between neighbours and a loop
// closure every 7th pose, its edges numbered as lines of "chain.g2o".
io::Graph Chain2D(int n) {
  io::Graph g;
  g.name = "chain.g2o";
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.05);
  int line = 0;
  for (int i = 0; i < n; ++i) {
    io::Vertex v;
    v.id = i;
    v.kind = io::VertexKind::kSE2;
    v.estimate = Eigen::Vector3d(i + noise(rng), noise(rng), noise(rng));
    v.line = ++line;
    g.AddVertex(v);
  }
  auto edge = [&](int a, int b) {
    io::Edge e;
    e.kind = io::EdgeKind::kSE2;
    e.from = a;
    e.to = b;
    e.measurement = Eigen::Vector3d(b - a + noise(rng), noise(rng), noise(rng));
    e.information = Eigen::Vector3d(100 + a % 5, 50, 400).asDiagonal();
    e.information(0, 1) = e.information(1, 0) = 3;
    e.line = ++line;
    g.AddEdge(e);
  };
  for (int i = 0; i + 1 < n; ++i) {
    edge(i, i + 1);
    if (i >= 7 && i % 7 == 0) edge(i - 7, i);
  }
  return g;
}

// A graph's edges built with it make the problem the edges added one by one
// make, and the first refused edge in file order is the one reported.
TEST(PoseGraph, EdgesOfTheGraphMatchEdgesAddedOneByOne) {
  const io::Graph g = Chain2D(4000);  // about 4600 edges
  slam::PoseGraph built(g);
  io::Graph vertices_only = g;
  vertices_only.edges.clear();
  vertices_only.order.erase(
      std::remove_if(vertices_only.order.begin(), vertices_only.order.end(),
                     [](const auto& r) { return r.type == io::Graph::RecordType::kEdge; }),
      vertices_only.order.end());
  slam::PoseGraph one_by_one(vertices_only);
  for (const io::Edge& e : g.edges) one_by_one.AddEdge(e);
  Problem& p = built.problem();
  Problem& q = one_by_one.problem();
  ASSERT_EQ(p.num_measurements(), q.num_measurements());
  for (int k = 0; k < p.num_measurements(); ++k) {
    ASSERT_EQ(p.measurement_variables(k), q.measurement_variables(k)) << k;
    ASSERT_EQ(p.measurement_name(k), q.measurement_name(k)) << k;
    ASSERT_EQ(p.Residual(k), q.Residual(k)) << k;
  }
  EXPECT_NEAR(2 * p.Cost(), built.Chi2(), 1e-9 * built.Chi2());

  io::Graph bad = g;
  bad.edges[4000].information(2, 2) = -1;
  bad.edges[2000].information(1, 1) = 0;  // the first: reported
  try {
    slam::PoseGraph refused(bad);
    FAIL() << "a graph with non-positive-definite information was built";
  } catch (const ParseError& e) {
    const io::Edge& first = bad.edges[2000];
    EXPECT_THAT(std::string(e.what()),
                ::testing::HasSubstr("chain.g2o:" + std::to_string(first.line) + ": edge " +
                                     std::to_string(first.from) + "-" + std::to_string(first.to)));
  }
}

// Chain2D with wrong loop closures: each says a pose 20 poses back lies 6 m
// aside, so χ²/dof ≫ 1 and the least-squares objective has several minima.
io::Graph ChainWithWrongClosures(int n) {
  io::Graph g = Chain2D(n);
  int line = static_cast<int>(g.vertices.size() + g.edges.size());
  for (int i = 25; i < n; i += 37) {
    io::Edge e;
    e.kind = io::EdgeKind::kSE2;
    e.from = i - 20;
    e.to = i;
    e.measurement = Eigen::Vector3d(14, 6, 1.0);
    e.information = Eigen::Vector3d(100, 100, 400).asDiagonal();
    e.line = ++line;
    g.AddEdge(e);
  }
  return g;
}

// An implausible solution is sought again from a Huber solution: the kept
// estimate is the lowest of the solves, the gauge stays, and a callback sees
// one run (iterations and time counting on) of the plain objective.
TEST(PoseGraph, ImplausibleSolutionRestartsAndKeepsTheLowest) {
  const io::Graph g = ChainWithWrongClosures(300);
  SolverOptions o = slam::DefaultSolverOptions();

  slam::PoseGraph once(g);
  const SolveSummary single = once.Solve(o);
  ASSERT_TRUE(single.usable);
  EXPECT_GT(once.Chi2PerDof(), slam::kImplausibleChi2PerDof);
  EXPECT_THAT(single.message, ::testing::Not(::testing::HasSubstr("kept the lowest")));

  // The lowest least-squares minimum is outlier mode 'off' (auto judges the
  // loop closures instead: outlier_rejection_test.cc).
  slam::OutlierOptions off;
  off.mode = slam::OutlierMode::kOff;
  slam::PoseGraph pg(g);
  pg.set_outlier_options(off);
  pg.set_restart_when_implausible(true);
  const Eigen::Vector3d gauge(pg.problem().value(pg.variable(0)));
  std::vector<IterationInfo> seen;
  o.on_iteration = [&](const IterationInfo& i) {
    seen.push_back(i);
    return true;
  };
  const SolveSummary s = pg.Solve(o);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_THAT(s.message, ::testing::HasSubstr("from a Huber solution"));
  // At least one round from the lowest solution so far, stopping when one
  // does not lower the objective.
  EXPECT_THAT(s.message, ::testing::HasSubstr("from a Huber solve from the lowest"));
  EXPECT_FALSE(pg.restart_when_implausible());  // only the first solve restarts
  EXPECT_LE(pg.Chi2(), once.Chi2() * (1 + 1e-9));
  EXPECT_NEAR(2 * s.final_cost, pg.Chi2(), 1e-9 * pg.Chi2());
  EXPECT_EQ(Eigen::Vector3d(pg.problem().value(pg.variable(0))), gauge);
  ASSERT_GT(seen.size(), static_cast<size_t>(single.iterations + 2));
  for (size_t k = 1; k < seen.size(); ++k) {
    EXPECT_GT(seen[k].iteration, seen[k - 1].iteration) << k;
    EXPECT_GE(seen[k].cumulative_time_s, seen[k - 1].cumulative_time_s) << k;
  }
  // The Huber solve's iterations report the plain χ² (their Huber cost is
  // far lower: the wrong closures' terms grow linearly there).
  const IterationInfo& huber_start = seen[single.iterations + 1];
  EXPECT_NEAR(huber_start.cost, seen[0].cost, 1e-9 * seen[0].cost);

  // Stopped in the second solve: the lowest estimate so far is kept.
  slam::PoseGraph stopped(g);
  stopped.set_outlier_options(off);
  stopped.set_restart_when_implausible(true);
  o.on_iteration = [&](const IterationInfo& i) { return i.iteration < single.iterations + 4; };
  const SolveSummary t = stopped.Solve(o);
  EXPECT_EQ(t.termination, "interrupted");
  EXPECT_TRUE(t.usable);
  EXPECT_LE(stopped.Chi2(), once.Chi2() * (1 + 1e-9));

  // A plausible graph is solved once.
  slam::PoseGraph plain(Chain2D(300));
  plain.set_restart_when_implausible(true);
  o.on_iteration = nullptr;
  EXPECT_THAT(plain.Solve(o).message, ::testing::Not(::testing::HasSubstr("kept the lowest")));
}

// Every loss: ρ(0) = 0, ρ'(0) = 1 (least squares near zero), ρ' and ρ'' the
// derivatives of ρ (central differences), on both sides of the width.
TEST(PoseGraph, RobustKernelDerivativesMatchFiniteDifferences) {
  for (const std::string& name : LossNames()) {
    if (name == "none") continue;
    for (double width : {0.5, 1.0, 3.0}) {
      const auto loss = MakeLoss(name, width);
      double r0[3];
      loss->Evaluate(0.0, r0);
      EXPECT_NEAR(r0[0], 0.0, 1e-15) << name;
      EXPECT_NEAR(r0[1], 1.0, 1e-12) << name;
      for (double s : {0.01, 0.2, 0.9, 1.7, 4.0, 30.0, 400.0}) {
        const double x = s * width * width, h = 1e-6 * std::max(1.0, x);
        double lo[3], mid[3], hi[3];
        loss->Evaluate(x - h, lo);
        loss->Evaluate(x, mid);
        loss->Evaluate(x + h, hi);
        EXPECT_NEAR(mid[1], (hi[0] - lo[0]) / (2 * h), 1e-6 * std::max(1.0, mid[1]))
            << name << " at s = " << x;
        if (std::abs(x - width * width) > 2 * h) {  // ρ'' jumps at the width (huber, dcs)
          EXPECT_NEAR(mid[2], (hi[1] - lo[1]) / (2 * h), 1e-5) << name << " at s = " << x;
        }
      }
    }
  }
}

// DCS is the M-estimator whose weight is the square of DCS' scale factor
// min(1, 2Φ/(Φ + χ²)) (Agarwal et al. 2013), Φ = width²; bounded by 3Φ.
TEST(PoseGraph, DcsWeightIsTheSquaredScaleFactor) {
  const double phi = 2.25;
  const auto dcs = MakeLoss("dcs", 1.5);
  for (double chi2 : {0.5, 2.25, 5.0, 100.0, 1e6}) {
    double rho[3];
    dcs->Evaluate(chi2, rho);
    const double scale = std::min(1.0, 2 * phi / (phi + chi2));
    EXPECT_NEAR(rho[1], scale * scale, 1e-15);
    EXPECT_LE(rho[0], 3 * phi);
  }
  double far[3];
  MakeLoss("geman_mcclure", 1.5)->Evaluate(1e12, far);
  EXPECT_NEAR(far[0], phi, 1e-6);  // Geman-McClure is bounded by δ²
}

TEST(PoseGraph, RobustKernelsByName) {
  for (const char* k : {"huber", "cauchy", "tukey", "arctan", "softl1", "dcs", "gm"}) {
    EXPECT_NE(MakeLoss(k, 1.0), nullptr);
  }
  EXPECT_EQ(MakeLoss("none", 1.0), nullptr);
  EXPECT_THROW(MakeLoss("huber", 0.0), Error);
  EXPECT_THROW(MakeLoss("bogus", 1.0), Error);
}

// A noise-free 3D graph (a ring with chords): both initialisations must give
// back the truth exactly, whatever the file's estimate.
TEST(Initialization, RecoverANoiseFreeGraph) {
  std::mt19937 rng(1);
  io::Graph g;
  std::vector<SE3> truth;
  const int n = 30;
  for (int i = 0; i < n; ++i) {
    truth.push_back(SE3::FromAmbient(RandomSE3(rng).data()));
    io::Vertex v;
    v.id = 100 + i;
    v.kind = io::VertexKind::kSE3;
    v.estimate = (i == 0 ? truth[0] : SE3()).ambient();
    g.AddVertex(v);
  }
  auto add = [&](int i, int j) {
    io::Edge e;
    e.kind = io::EdgeKind::kSE3;
    e.from = 100 + i;
    e.to = 100 + j;
    e.measurement = (truth[i].inverse() * truth[j]).ambient();
    e.information = Eigen::MatrixXd::Identity(6, 6);
    g.AddEdge(e);
  };
  for (int i = 0; i + 1 < n; ++i) add(i, i + 1);
  for (int i = 0; i + 5 < n; i += 3) add(i + 5, i);
  for (auto method : {slam::InitMethod::kSpanningTree, slam::InitMethod::kChordal}) {
    io::Graph h = g;
    slam::Initialize(&h, method);
    for (int i = 0; i < n; ++i) {
      const SE3 x = SE3::FromAmbient(h.vertices[i].estimate.data());
      EXPECT_LT(x.boxminus(truth[i]).norm(), 1e-8) << i;
    }
  }
}

// The chordal relaxation against a dense solve of its own least squares
// (rows of the rotations, projected by the SVD; then the translations'
// Laplacian) on noisy 2D and 3D graphs with unequal weights: the 2D path
// solves it as complex numbers, both reuse one ordering, the oracle does not.
TEST(Initialization, ChordalSolvesTheRelaxationsLeastSquares) {
  for (const int d : {2, 3}) {
    std::mt19937 rng(7 + d);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::uniform_real_distribution<double> uni(-3.0, 3.0);
    const int n = 25;
    io::Graph g;
    for (int i = 0; i < n; ++i) {
      io::Vertex v;
      v.id = i;
      v.kind = d == 2 ? io::VertexKind::kSE2 : io::VertexKind::kSE3;
      v.estimate =
          d == 2 ? Eigen::VectorXd(SE2(Eigen::Vector2d(uni(rng), uni(rng)), uni(rng)).ambient())
                 : Eigen::VectorXd(SE3::FromAmbient(RandomSE3(rng).data()).ambient());
      g.AddVertex(v);
    }
    auto add = [&](int i, int j) {
      io::Edge e;
      e.kind = d == 2 ? io::EdgeKind::kSE2 : io::EdgeKind::kSE3;
      e.from = i;
      e.to = j;
      const int t = d == 2 ? 3 : 6;
      Eigen::VectorXd delta(t);
      for (int k = 0; k < t; ++k) delta[k] = uni(rng) + noise(rng);
      e.measurement = d == 2 ? Eigen::VectorXd(SE2().boxplus(delta).ambient())
                             : Eigen::VectorXd(SE3().boxplus(delta).ambient());
      Eigen::MatrixXd A = Eigen::MatrixXd::Random(t, t);
      e.information = A * A.transpose() + Eigen::MatrixXd::Identity(t, t);
      g.AddEdge(e);
    };
    for (int i = 0; i + 1 < n; ++i) add(i, i + 1);
    for (int i = 0; i + 4 < n; i += 2) add(i + 4, i);

    // The oracle: unknowns of poses 1..n−1 (pose 0 is the root).
    const int m = n - 1;
    auto rot = [&](const Eigen::VectorXd& x) -> Eigen::MatrixXd {
      return d == 2 ? Eigen::MatrixXd(SE2::FromAmbient(x.data()).transform().topLeftCorner(2, 2))
                    : Eigen::MatrixXd(SE3::FromAmbient(x.data()).transform().topLeftCorner(3, 3));
    };
    const Eigen::MatrixXd R0 = rot(g.vertices[0].estimate);
    const Eigen::VectorXd t0 = g.vertices[0].estimate.head(d);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m * d, m * d), b = Eigen::MatrixXd::Zero(m * d, d);
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(m, m);
    for (const io::Edge& e : g.edges) {
      const ChordalPrecisions p = ChordalPrecisionsOfInformation(e.information);
      const Eigen::MatrixXd Z = rot(e.measurement);
      const int i = e.from - 1, j = e.to - 1;  // −1: the root
      // ‖X_j − Zᵀ X_i‖² with X_u = R_uᵀ (its columns are R_u's rows).
      if (i >= 0) H.block(i * d, i * d, d, d) += p.kappa * Eigen::MatrixXd::Identity(d, d);
      if (j >= 0) H.block(j * d, j * d, d, d) += p.kappa * Eigen::MatrixXd::Identity(d, d);
      if (i >= 0 && j >= 0) {
        H.block(i * d, j * d, d, d) -= p.kappa * Z;
        H.block(j * d, i * d, d, d) -= p.kappa * Z.transpose();
      } else if (j >= 0) {
        b.block(j * d, 0, d, d) += p.kappa * Z.transpose() * R0.transpose();
      } else {
        b.block(i * d, 0, d, d) += p.kappa * Z * R0.transpose();
      }
      if (i >= 0) L(i, i) += p.tau;
      if (j >= 0) L(j, j) += p.tau;
      if (i >= 0 && j >= 0) L(i, j) = L(j, i) = L(i, j) - p.tau;
    }
    const Eigen::MatrixXd X = H.ldlt().solve(b);
    std::vector<Eigen::MatrixXd> R(n, R0);
    for (int u = 0; u < m; ++u) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(X.block(u * d, 0, d, d).transpose(),
                                            Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::MatrixXd D = Eigen::MatrixXd::Identity(d, d);
      D(d - 1, d - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
      R[u + 1] = svd.matrixU() * D * svd.matrixV().transpose();
    }
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(m, d);
    for (const io::Edge& e : g.edges) {
      const double tau = ChordalPrecisionsOfInformation(e.information).tau;
      const Eigen::VectorXd tij = R[e.from] * e.measurement.head(d);  // t_j − t_i ≈ R_i t_ij
      const int i = e.from - 1, j = e.to - 1;
      if (i >= 0) c.row(i) -= tau * tij.transpose();
      if (j >= 0) c.row(j) += tau * tij.transpose();
      if (i < 0) c.row(j) += tau * t0.transpose();
      if (j < 0) c.row(i) += tau * t0.transpose();
    }
    const Eigen::MatrixXd t = L.ldlt().solve(c);

    io::Graph h = g;
    slam::InitializeChordal(&h);
    for (int u = 0; u < m; ++u) {
      const Eigen::VectorXd& x = h.vertices[u + 1].estimate;
      EXPECT_LT((rot(x) - R[u + 1]).norm(), 1e-9) << d << "D pose " << u + 1;
      EXPECT_LT((x.head(d) - t.row(u).transpose()).norm(), 1e-8) << d << "D pose " << u + 1;
    }
  }
}

TEST(Initialization, ChordalOnARealFileLowersTheObjective) {
  io::Graph g = io::ReadG2o(kData + "smallGrid3D.g2o");
  slam::PoseGraph before(g);
  slam::Initialize(&g, slam::InitMethod::kChordal);
  slam::PoseGraph after(g);
  EXPECT_LT(after.Chi2(), 0.1 * before.Chi2());
  EXPECT_THROW(slam::ParseInitMethod("magic"), Error);
}

}  // namespace
}  // namespace boxplus
