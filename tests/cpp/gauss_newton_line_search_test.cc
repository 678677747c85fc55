// Tests of boxplus' Gauss–Newton with a backtracking line search
// (Method::kGaussNewtonLineSearch): the same optima as Ceres' trust-region
// solvers, a line search that really backtracks, robust losses, gauge
// freedom, fixed and unused variables, interruption and evaluation failures.
#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "boxplus/boxplus.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/slam/initialization.h"
#include "boxplus/slam/pose_graph.h"

namespace boxplus {
namespace {

const std::string kData = std::string(BOXPLUS_SOURCE_DIR) + "/tests/data/";

SolverOptions LineSearch() {
  SolverOptions o;
  o.method = Method::kGaussNewtonLineSearch;
  return o;
}

// A pose graph solved by the line search and by Levenberg–Marquardt ends at
// the same objective and the same poses.
TEST(GaussNewtonLineSearch, PoseGraphsReachTheTrustRegionOptimum) {
  for (const char* file : {"tinyGrid3D.g2o", "smallGrid3D.g2o", "CSAIL.g2o"}) {
    for (auto conv : {PoseErrorConvention::kG2o, PoseErrorConvention::kLog}) {
      slam::PoseGraphOptions po;
      po.convention = conv;
      io::Graph graph = io::ReadG2o(kData + file);
      if (!graph.estimates_from_file) slam::Initialize(&graph, slam::InitMethod::kSpanningTree);
      slam::PoseGraph ls(graph, po);
      slam::PoseGraph lm(graph, po);
      SolverOptions o = LineSearch();
      o.function_tolerance = 1e-14;
      const SolveSummary s = ls.Solve(o);
      ASSERT_TRUE(s.usable) << file << "\n" << s.report;
      SolverOptions t = slam::DefaultSolverOptions();
      t.function_tolerance = 1e-14;
      ASSERT_TRUE(lm.Solve(t).usable);
      EXPECT_NEAR(ls.Chi2(), lm.Chi2(), 1e-8 * lm.Chi2()) << file << " " << ToString(conv);
      EXPECT_NEAR(2 * s.final_cost, ls.Chi2(), 1e-9 * ls.Chi2()) << file;
      for (int v = 0; v < ls.problem().num_variables(); ++v) {
        const auto& m = ls.problem().manifold(v);
        Eigen::VectorXd d(m.TangentSize());
        ASSERT_TRUE(m.Minus(ls.problem().value(v), lm.problem().value(v), d.data()));
        EXPECT_LT(d.norm(), 1e-5) << file << " variable " << v;
      }
    }
  }
}

// r(x) = atan(x): from x = 3 the full Gauss–Newton step (−r/r') overshoots to
// |x| > 3 where |r| is larger; only a shortened step decreases the cost.
struct Atan {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = atan(x[0]);
    return true;
  }
};

TEST(GaussNewtonLineSearch, BacktracksWhenTheFullStepOvershoots) {
  Problem p;
  const double x0 = 3.0;
  const int x = p.AddVariable(MakeManifold("Rn", 1), &x0, "x");
  p.AddMeasurement(std::make_shared<ceres::AutoDiffCostFunction<Atan, 1, 1>>(new Atan), {x});
  SolverOptions o = LineSearch();
  double shortest = 1.0;
  o.on_iteration = [&shortest](const IterationInfo& i) {
    if (i.iteration > 0) shortest = std::min(shortest, i.trust_region_radius);
    return true;
  };
  const SolveSummary s = p.Solve(o);
  ASSERT_TRUE(s.usable) << s.report;
  EXPECT_EQ(s.termination, "convergence") << s.message;
  EXPECT_LT(shortest, 1.0);  // at least one step was halved
  EXPECT_LT(std::abs(p.value(x)[0]), 1e-6);
  EXPECT_LT(s.final_cost, s.initial_cost);
}

// A robust loss: the line search minimises ½ Σ ρ(‖r‖²) (the gradient is
// exact), so it ends where Levenberg–Marquardt does.
struct Offset {
  double z;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = x[0] - T(z);
    r[1] = x[1] - T(2 * z);
    return true;
  }
};

TEST(GaussNewtonLineSearch, RobustLossSameMinimumAsLevenbergMarquardt) {
  const double data[] = {0.1, -0.2, 0.05, 0.15, -0.1, 8.0, 9.0};  // two outliers
  double cost[2];
  Eigen::Vector2d sol[2];
  for (int k = 0; k < 2; ++k) {
    Problem p;
    const double x0[2] = {3.0, -1.0};
    const int x = p.AddVariable(MakeManifold("Rn", 2), x0);
    for (double z : data) {
      p.AddMeasurement(std::make_shared<ceres::AutoDiffCostFunction<Offset, 2, 2>>(new Offset{z}),
                       {x}, std::make_shared<ceres::CauchyLoss>(0.5));
    }
    SolverOptions o = k == 0 ? LineSearch() : SolverOptions();
    o.function_tolerance = o.gradient_tolerance = o.parameter_tolerance = 1e-15;
    const SolveSummary s = p.Solve(o);
    ASSERT_TRUE(s.usable) << s.report;
    cost[k] = s.final_cost;
    sol[k] = Eigen::Map<const Eigen::Vector2d>(p.value(x));
  }
  EXPECT_NEAR(cost[0], cost[1], 1e-10 * cost[1]);
  EXPECT_LT((sol[0] - sol[1]).norm(), 1e-6);
  EXPECT_LT(std::abs(sol[0][0]), 0.2);  // the outliers do not drag the estimate
}

// No gauge fixed: JᵀJ is singular along the common motion of both poses; the
// step is regularised and the residual still goes to zero.
TEST(GaussNewtonLineSearch, SingularNormalEquationsAreRegularised) {
  Problem p;
  const SE2 a(Eigen::Vector2d(0, 0), 0.0), b(Eigen::Vector2d(3, 1), 1.0);
  const int xa = p.AddVariable(MakeManifold("SE2"), a.data(), "a");
  const int xb = p.AddVariable(MakeManifold("SE2"), b.data(), "b");
  const Eigen::Vector3d z(1.0, 0.5, 0.2);
  p.AddMeasurement(MakeRelativePose2D(z, NoiseModel::Unit(3), PoseErrorConvention::kG2o), {xa, xb});
  const SolveSummary s = p.Solve(LineSearch());
  ASSERT_TRUE(s.usable) << s.report;
  EXPECT_LT(p.Cost(), 1e-12);
}

TEST(GaussNewtonLineSearch, FixedAndUnusedVariablesDoNotMove) {
  Problem p;
  const SE2 a(Eigen::Vector2d(1, 1), 0.5), b(Eigen::Vector2d(2, 0), 0.1),
      c(Eigen::Vector2d(7, 7), 2.0);
  const int xa = p.AddVariable(MakeManifold("SE2"), a.data(), "a");
  const int xb = p.AddVariable(MakeManifold("SE2"), b.data(), "b");
  const int xc = p.AddVariable(MakeManifold("SE2"), c.data(), "unused");
  p.SetFixed(xa);
  p.AddMeasurement(
      MakeRelativePose2D(Eigen::Vector3d(1, 0, 0), NoiseModel::Unit(3), PoseErrorConvention::kG2o),
      {xa, xb});
  const SolveSummary s = p.Solve(LineSearch());
  ASSERT_TRUE(s.usable) << s.report;
  EXPECT_EQ(SE2::FromAmbient(p.value(xa)).boxminus(a).norm(), 0.0);
  EXPECT_EQ(SE2::FromAmbient(p.value(xc)).boxminus(c).norm(), 0.0);
  EXPECT_LT(p.Cost(), 1e-12);
}

TEST(GaussNewtonLineSearch, CallbackStopsAtAnAcceptedPoint) {
  slam::PoseGraph pg(io::ReadG2o(kData + "smallGrid3D.g2o"));
  SolverOptions o = LineSearch();
  double reported = 0.0;
  o.on_iteration = [&reported](const IterationInfo& i) {
    reported = i.cost;
    return i.iteration < 2;
  };
  const SolveSummary s = pg.Solve(o);
  EXPECT_EQ(s.termination, "interrupted");
  EXPECT_TRUE(s.usable);
  EXPECT_EQ(s.iterations, 2);
  EXPECT_NEAR(pg.problem().Cost(), reported, 1e-9 * reported);
  EXPECT_LT(reported, s.initial_cost);
}

// should_stop is asked within an iteration: a stop requested after the second
// iteration's linear solve ends the solve before that iteration's line search,
// at the first iteration's accepted point (Ctrl-C waits for one linear solve).
TEST(GaussNewtonLineSearch, StopWithinAnIterationKeepsTheAcceptedPoint) {
  slam::PoseGraph pg(io::ReadG2o(kData + "smallGrid3D.g2o"));
  SolverOptions o = LineSearch();
  double after_first = 0.0;
  int iterations_seen = 0, asked = 0;
  o.on_iteration = [&](const IterationInfo& i) {
    iterations_seen = i.iteration;
    if (i.iteration == 1) after_first = i.cost;
    return true;
  };
  o.should_stop = [&] { return iterations_seen >= 1 && ++asked >= 1; };
  const SolveSummary s = pg.Solve(o);
  EXPECT_EQ(s.termination, "interrupted");
  EXPECT_TRUE(s.usable);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_EQ(iterations_seen, 1);  // the second iteration never reported
  EXPECT_NEAR(pg.problem().Cost(), after_first, 1e-9 * after_first);
  EXPECT_NEAR(s.final_cost, after_first, 1e-9 * after_first);
}

// A measurement that cannot be evaluated away from the start: trial points
// there are rejected and the estimate stays at the last evaluable point.
struct OnlyNearZero {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = x[0] - T(5.0);
    return abs(x[0]) < T(1.0);
  }
};

TEST(GaussNewtonLineSearch, FailedEvaluationsShortenTheStep) {
  Problem p;
  const double x0 = 0.0;
  const int x = p.AddVariable(MakeManifold("Rn", 1), &x0);
  p.AddMeasurement(
      std::make_shared<ceres::AutoDiffCostFunction<OnlyNearZero, 1, 1>>(new OnlyNearZero), {x});
  const SolveSummary s = p.Solve(LineSearch());
  EXPECT_TRUE(s.usable) << s.report;
  EXPECT_GT(p.value(x)[0], 0.5);  // moved towards 5 as far as it can be evaluated
  EXPECT_LT(p.value(x)[0], 1.0);
  EXPECT_NEAR(p.Cost(), s.final_cost, 1e-12);
}

TEST(GaussNewtonLineSearch, UnevaluableStartFails) {
  Problem p;
  const double x0 = 3.0;
  const int x = p.AddVariable(MakeManifold("Rn", 1), &x0);
  p.AddMeasurement(
      std::make_shared<ceres::AutoDiffCostFunction<OnlyNearZero, 1, 1>>(new OnlyNearZero), {x});
  const SolveSummary s = p.Solve(LineSearch());
  EXPECT_EQ(s.termination, "failure");
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(p.value(x)[0], 3.0);
}

// Two threads share the terms: the same iterations, the same optimum to
// rounding (the sums of H and g are taken in another order), on a 2D and a
// 3D graph large enough to be split (≥ 2 × 512 terms).
// A 3D helix of 600 poses, odometry and a loop closure every 10 poses to the
// pose one turn (50 poses) back, measured without noise; the estimates are
// the truth with seeded perturbations.
std::string WriteHelix() {
  const std::string path = ::testing::TempDir() + "/helix3d.g2o";
  std::ofstream out(path);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Eigen::Isometry3d> truth;
  for (int i = 0; i < 600; ++i) {
    const double a = 2 * M_PI * i / 50.0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translate(Eigen::Vector3d(10 * std::cos(a), 10 * std::sin(a), 0.1 * i));
    T.rotate(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()));
    truth.push_back(T);
    const Eigen::Quaterniond q(
        (T.rotation() * Eigen::AngleAxisd(noise(rng), Eigen::Vector3d::UnitX())).matrix());
    const Eigen::Vector3d t = T.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    out << "VERTEX_SE3:QUAT " << i << " " << t.x() << " " << t.y() << " " << t.z() << " " << q.x()
        << " " << q.y() << " " << q.z() << " " << q.w() << "\n";
  }
  auto edge = [&](int i, int j) {
    const Eigen::Isometry3d z = truth[i].inverse() * truth[j];
    const Eigen::Quaterniond q(z.rotation());
    out << "EDGE_SE3:QUAT " << i << " " << j << " " << z.translation().x() << " "
        << z.translation().y() << " " << z.translation().z() << " " << q.x() << " " << q.y() << " "
        << q.z() << " " << q.w();
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) out << (r == c ? (r < 3 ? " 100" : " 400") : " 0");
    }
    out << "\n";
  };
  for (int i = 0; i + 1 < 600; ++i) edge(i, i + 1);
  for (int i = 50; i < 600; i += 10) edge(i - 50, i);
  for (int i = 0; i + 2 < 600; ++i) edge(i, i + 2);
  return path;
}

TEST(GaussNewtonLineSearch, TwoThreadsReachTheSameOptimum) {
  for (const std::string file : {kData + "CSAIL.g2o", WriteHelix()}) {
    io::Graph graph = io::ReadG2o(file);
    if (!graph.estimates_from_file) slam::Initialize(&graph, slam::InitMethod::kSpanningTree);
    ASSERT_GE(graph.edges.size(), 1024u) << file;
    slam::PoseGraph one(graph), two(graph);
    SolverOptions o = LineSearch();
    o.function_tolerance = 1e-14;
    const SolveSummary s1 = one.Solve(o);
    o.num_threads = 2;
    const SolveSummary s2 = two.Solve(o);
    ASSERT_TRUE(s1.usable && s2.usable) << file;
    EXPECT_EQ(s1.iterations, s2.iterations) << file;
    EXPECT_NEAR(one.Chi2(), two.Chi2(), 1e-10 * one.Chi2()) << file;
    for (int v = 0; v < one.problem().num_variables(); ++v) {
      const auto& m = one.problem().manifold(v);
      Eigen::VectorXd d(m.TangentSize());
      ASSERT_TRUE(m.Minus(one.problem().value(v), two.problem().value(v), d.data()));
      EXPECT_LT(d.norm(), 1e-8) << file << " variable " << v;
    }
  }
}

// r = x − 1 that throws once x has moved (on whichever thread evaluates it).
struct ThrowsAfterMoving {
  bool operator()(const double* const* x, double* r, double** jacobians) const {
    if (x[0][0] != 0.0) throw Error("term evaluated away from the start");
    r[0] = x[0][0] - 1.0;
    if (jacobians && jacobians[0]) jacobians[0][0] = 1.0;
    return true;
  }
};

class ThrowingCost : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit ThrowingCost(bool throws) : throws_(throws) {}
  bool Evaluate(const double* const* x, double* r, double** j) const override {
    if (throws_) return ThrowsAfterMoving()(x, r, j);
    r[0] = x[0][0] - 1.0;
    if (j && j[0]) j[0][0] = 1.0;
    return true;
  }

 private:
  bool throws_;
};

// An exception thrown by a term on the second thread reaches the caller (and
// the values are left at the accepted point), and a term that fails there
// fails the evaluation as it does on one thread.
TEST(GaussNewtonLineSearch, ThreadsPassOnExceptionsAndFailures) {
  Problem p;
  std::vector<int> xs;
  const double x0 = 0.0;
  for (int i = 0; i < 2048; ++i) xs.push_back(p.AddVariable(MakeManifold("Rn", 1), &x0));
  for (int i = 0; i < 2048; ++i) {
    p.AddMeasurement(std::make_shared<ThrowingCost>(i == 2047), {xs[i]});
  }
  SolverOptions o = LineSearch();
  o.num_threads = 2;
  EXPECT_THROW(p.Solve(o), Error);
  for (int x : xs) EXPECT_EQ(p.value(x)[0], 0.0);

  Problem q;
  const double y0 = 3.0;
  std::vector<int> ys;
  for (int i = 0; i < 2048; ++i) ys.push_back(q.AddVariable(MakeManifold("Rn", 1), &y0));
  for (int i = 0; i < 2048; ++i) {
    if (i == 2047) {
      q.AddMeasurement(
          std::make_shared<ceres::AutoDiffCostFunction<OnlyNearZero, 1, 1>>(new OnlyNearZero),
          {ys[i]});
    } else {
      q.AddMeasurement(std::make_shared<ThrowingCost>(false), {ys[i]});
    }
  }
  const SolveSummary s = q.Solve(o);
  EXPECT_EQ(s.termination, "failure");
  EXPECT_FALSE(s.usable);
}

}  // namespace
}  // namespace boxplus
