// End-to-end smoke tests of boxplus::Problem through Ceres: averaging noisy
// SO(3)/SE(3) observations has closed-form answers to check against.
#include <random>

#include <gtest/gtest.h>

#include "boxplus/boxplus.h"

namespace boxplus {
namespace {

// Tolerances tight enough that the solver stops only when no step helps.
SolverOptions Tight() {
  SolverOptions o;
  o.function_tolerance = 1e-16;
  o.gradient_tolerance = 1e-16;
  o.parameter_tolerance = 1e-16;
  return o;
}

Eigen::Vector3d RandomVec(std::mt19937& rng, double scale) {
  std::normal_distribution<double> g(0, scale);
  return {g(rng), g(rng), g(rng)};
}

// Observations R·exp(±δₖ) in symmetric pairs: the mean is exactly R.
TEST(Problem, AveragingSymmetricRotationsGivesTheCentre) {
  std::mt19937 rng(11);
  const SO3 truth = SO3::Exp(Eigen::Vector3d(0.4, -1.2, 2.5));
  Problem p;
  const SO3 start;  // identity, far from the truth
  const int x = p.AddVariable(MakeManifold("SO3"), start.data(), "R");
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d d = RandomVec(rng, 0.3);
    for (double s : {1.0, -1.0}) {
      const SO3 z = truth.boxplus(s * d);
      p.AddMeasurement(PriorFunctor<SO3Ops>::Create(z.ambient(), Eigen::Matrix3d::Identity()), {x});
    }
  }
  const SolveSummary s = p.Solve(Tight());
  ASSERT_TRUE(s.usable) << s.report;
  EXPECT_EQ(s.termination, "convergence");
  // The cost (≈ 1) resolves steps down to ~1e-16, i.e. errors of ~1e-8 rad.
  EXPECT_LT(SO3::FromAmbient(p.value(x)).boxminus(truth).norm(), 1e-7);
}

// Weighted SE(3) mean: position = information-weighted mean of positions;
// rotation = Karcher mean, where Σ wᵢ log(R⁻¹ zᵢ) = 0.
TEST(Problem, AveragingPosesMatchesClosedForm) {
  std::mt19937 rng(12);
  const SE3 truth(SO3::Exp(Eigen::Vector3d(-0.5, 0.2, 1.0)), Eigen::Vector3d(1, 2, 3));
  Problem p;
  const SE3 start;
  const int x = p.AddVariable(MakeManifold("SE3"), start.data(), "pose");
  std::vector<SE3> zs;
  std::vector<double> ws;
  Eigen::Vector3d weighted_pos = Eigen::Vector3d::Zero();
  double wsum = 0;
  for (int k = 0; k < 25; ++k) {
    Eigen::Matrix<double, 6, 1> d;
    d << RandomVec(rng, 0.5), RandomVec(rng, 0.2);
    zs.push_back(truth.boxplus(d));
    const double sigma = 0.1 + 0.1 * k;
    ws.push_back(1.0 / (sigma * sigma));
    weighted_pos += ws.back() * zs.back().pos();
    wsum += ws.back();
    const Eigen::MatrixXd W =
        NoiseModel::Covariance(Eigen::MatrixXd::Identity(6, 6) * sigma * sigma, "z")
            .sqrt_information();
    p.AddMeasurement(PriorFunctor<SE3Ops>::Create(zs.back().ambient(), W), {x});
  }
  const SolveSummary s = p.Solve(Tight());
  ASSERT_TRUE(s.usable) << s.report;
  const SE3 est = SE3::FromAmbient(p.value(x));
  EXPECT_LT((est.pos() - weighted_pos / wsum).norm(), 1e-9);
  Eigen::Vector3d karcher = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < zs.size(); ++k) {
    karcher += ws[k] * zs[k].rotation().boxminus(est.rotation());
  }
  EXPECT_LT(karcher.norm() / wsum, 1e-9);

  // Covariance of a mean of independent isotropic observations: (Σ wᵢ)⁻¹ I.
  const Eigen::MatrixXd C = p.Covariance(x);
  ASSERT_EQ(C.rows(), 6);
  EXPECT_LT((C.topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity() / wsum).norm(), 1e-9);
  EXPECT_NEAR(C(3, 3), 1.0 / wsum, 1e-2 / wsum);  // rotation: up to curvature
}

TEST(Problem, FixedVariablesDoNotMove) {
  Problem p;
  const SE2 a(Eigen::Vector2d(1, 1), 0.5);
  const int x = p.AddVariable(MakeManifold("SE2"), a.data());
  p.SetFixed(x);
  const SE2 z(Eigen::Vector2d(5, 5), -1.0);
  p.AddMeasurement(PriorFunctor<SE2Ops>::Create(z.ambient(), Eigen::Matrix3d::Identity()), {x});
  p.Solve();
  EXPECT_EQ(SE2::FromAmbient(p.value(x)).boxminus(a).norm(), 0.0);
  EXPECT_THROW(p.Covariance(x), Error);
}

// Ceres' blocks are added on the first use of its problem (Cost, Jacobian,
// covariance, a trust-region solve): what is added or fixed before and after
// that use must all reach it.
TEST(Problem, CeresSeesWhatIsAddedOrFixedAfterItsFirstUse) {
  Problem p;
  const SE2 a(Eigen::Vector2d(1, 1), 0.5), za(Eigen::Vector2d(2, 0), 0.1);
  const SE2 b(Eigen::Vector2d(-1, 3), -0.5), zb(Eigen::Vector2d(0, 2), 0.3);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const int x = p.AddVariable(MakeManifold("SE2"), a.data());
  p.AddMeasurement(PriorFunctor<SE2Ops>::Create(za.ambient(), I), {x});
  const double ca = 0.5 * a.boxminus(za).squaredNorm();
  EXPECT_NEAR(p.Cost(), ca, 1e-12);  // the first use

  const int y = p.AddVariable(MakeManifold("SE2"), b.data());
  p.SetFixed(y);  // before Ceres holds y
  p.AddMeasurement(PriorFunctor<SE2Ops>::Create(zb.ambient(), I), {y});
  EXPECT_NEAR(p.Cost(), ca + 0.5 * b.boxminus(zb).squaredNorm(), 1e-12);
  const JacobianEvaluation j = p.EvaluateJacobian();
  EXPECT_EQ(j.jacobian.rows(), 6);
  EXPECT_EQ(j.jacobian.cols(), 3);  // y is fixed

  SolverOptions lm = Tight();
  lm.method = Method::kLevenbergMarquardt;
  p.Solve(lm);
  EXPECT_LT(SE2::FromAmbient(p.value(x)).boxminus(za).norm(), 1e-8);
  EXPECT_EQ(SE2::FromAmbient(p.value(y)).boxminus(b).norm(), 0.0);

  p.SetFixed(y, false);  // after Ceres holds y
  p.Solve(lm);
  EXPECT_LT(SE2::FromAmbient(p.value(y)).boxminus(zb).norm(), 1e-8);
  EXPECT_NEAR(p.Cost(), 0.0, 1e-14);
}

TEST(Problem, BadInputRaisesNamedErrors) {
  Problem p;
  const SO3 r;
  const int x = p.AddVariable(MakeManifold("SO3"), r.data(), "R");
  auto cost = PriorFunctor<SO3Ops>::Create(r.ambient(), Eigen::Matrix3d::Identity());
  try {
    p.AddMeasurement(cost, {7}, nullptr, "gyro");
    FAIL() << "expected IndexError";
  } catch (const IndexError& e) {
    EXPECT_NE(std::string(e.what()).find("'gyro'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(p.AddMeasurement(cost, {x, x}), Error);
  auto wrong =
      PriorFunctor<SE3Ops>::Create(SE3().ambient(), Eigen::Matrix<double, 6, 6>::Identity());
  EXPECT_THROW(p.AddMeasurement(wrong, {x}), Error);
  EXPECT_THROW(p.value(3), IndexError);
  Eigen::MatrixXd bad(2, 2);
  bad << 1, 2, 2, 1;  // symmetric, indefinite
  EXPECT_THROW(NoiseModel::Covariance(bad, "z"), Error);
  const double nan[4] = {0, 0, 0, std::nan("")};
  EXPECT_THROW(p.AddVariable(MakeManifold("SO3"), nan), Error);
}

TEST(Problem, IterationCallbackCanStopTheSolve) {
  Problem p;
  const SO3 start;
  const int x = p.AddVariable(MakeManifold("SO3"), start.data());
  p.AddMeasurement(PriorFunctor<SO3Ops>::Create(SO3::Exp(Eigen::Vector3d(2.0, 0.5, -0.3)).ambient(),
                                                Eigen::Matrix3d::Identity()),
                   {x});
  SolverOptions o;
  int calls = 0;
  o.on_iteration = [&calls](const IterationInfo&) { return ++calls < 1; };
  const SolveSummary s = p.Solve(o);
  EXPECT_EQ(s.termination, "interrupted");
  EXPECT_TRUE(s.usable);
  EXPECT_EQ(calls, 1);
}

}  // namespace
}  // namespace boxplus

namespace boxplus {
namespace {

// Errors() concatenates the errors (or residuals) of the measurements asked for,
// in the order asked, each un-whitened by its own NoiseModel, and runs the
// evaluation hooks once for all of them (Error() runs them once per call).
TEST(Problem, ErrorsOfSeveralMeasurementsRunTheHooksOnce) {
  Problem p;
  const Eigen::Vector2d start(1.0, 2.0);
  const int x = p.AddVariable(MakeManifold("Rn", 2), start.data(), "x");
  const NoiseModel a = NoiseModel::Sigmas(Eigen::Vector2d(0.5, 2.0));
  const NoiseModel b = NoiseModel::Covariance((Eigen::Matrix2d() << 4, 1, 1, 2).finished());
  const int ma = p.AddMeasurement(MakePrior(p.manifold(x), Eigen::Vector2d(0, 0), a, "a"), {x}, a);
  const int mb = p.AddMeasurement(MakePrior(p.manifold(x), Eigen::Vector2d(3, 3), b, "b"), {x}, b);
  int hook_calls = 0;
  p.AddEvaluationHook([&](bool, bool) { ++hook_calls; });
  const Eigen::VectorXd e = p.Errors({mb, ma});
  EXPECT_EQ(hook_calls, 1);
  ASSERT_EQ(e.size(), 4);
  EXPECT_NEAR((e.head<2>() - Eigen::Vector2d(-2, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((e.tail<2>() - Eigen::Vector2d(1, 2)).norm(), 0.0, 1e-12);
  const Eigen::VectorXd r = p.Errors({ma}, /*whitened=*/true);
  EXPECT_NEAR((r - Eigen::Vector2d(2, 1)).norm(), 0.0, 1e-12);
  EXPECT_THROW(p.Errors({ma, 7}), IndexError);
  EXPECT_EQ(p.Errors({}).size(), 0);
}

}  // namespace
}  // namespace boxplus
