// The rank test (determinedness.h) against dense SVDs on generated families
// of Jacobians with a planted null space, and through Problem: undetermined
// variables named with their directions, covariances of determined ones kept.
#include <random>

#include <ceres/dynamic_autodiff_cost_function.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "boxplus/boxplus.h"
#include "boxplus/determinedness.h"
#include "boxplus/factors/pose/relative_pose.h"

namespace boxplus {
namespace {

using ::testing::HasSubstr;
using Sparse = Eigen::SparseMatrix<double>;

template <class F>
void ExpectError(F&& f, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one saying: " << what;
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr(what));
  }
}

// A Jacobian of `variables` blocks of `dim` columns whose rows each touch two
// blocks (as relative measurements do), with columns scaled over six orders of
// magnitude (units), and a planted null space of dimension `nullity`: the rows
// are projected off a random subspace of that dimension.
struct Planted {
  Sparse jacobian;
  Eigen::MatrixXd null_space;  // orthonormal, in the original column scaling
};

Planted MakePlanted(std::mt19937& rng, int variables, int dim, int rows, int nullity) {
  const int n = variables * dim;
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> pick(0, variables - 1);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n);
  for (int r = 0; r < rows; ++r) {
    const int a = pick(rng);
    const int b = (a + 1 + pick(rng) % (variables - 1)) % variables;
    for (int c = 0; c < dim; ++c) {
      J(r, a * dim + c) = g(rng);
      J(r, b * dim + c) = g(rng);
    }
  }
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(n, nullity);
  if (nullity > 0) {
    // Null vectors supported on the first few variables only, so that the
    // rest stays determined and sparse.
    const int support = std::min(n, std::max(nullity + 2, 2 * dim));
    Eigen::MatrixXd R = Eigen::MatrixXd::NullaryExpr(support, nullity, [&] { return g(rng); });
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(R);
    N.topRows(support) = qr.householderQ() * Eigen::MatrixXd::Identity(support, nullity);
    J -= (J * N) * N.transpose();
  }
  Eigen::VectorXd units(n);
  for (int c = 0; c < n; ++c) units(c) = std::pow(10.0, (c % 7) - 3.0);
  J = J * units.cwiseInverse().asDiagonal();  // columns in other units
  // The null space in the new coordinates is units · N.
  Eigen::MatrixXd Nu = units.asDiagonal() * N;
  if (nullity > 0) {
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(Nu);
    Nu = qr.householderQ() * Eigen::MatrixXd::Identity(n, nullity);
  }
  return {J.sparseView(), Nu};
}

std::vector<int> Offsets(int variables, int dim) {
  std::vector<int> out;
  for (int v = 0; v < variables; ++v) out.push_back(v * dim);
  return out;
}
std::vector<int> Ids(int variables) {
  std::vector<int> out;
  for (int v = 0; v < variables; ++v) out.push_back(v);
  return out;
}

// Dense and sparse paths (≤ 64 and > 64 columns), tall and wide Jacobians.
TEST(Determinedness, FindsThePlantedNullSpaceOnAFamily) {
  std::mt19937 rng(7);
  int cases = 0;
  for (int variables : {3, 10, 40}) {
    for (int dim : {1, 3, 6}) {
      const int n = variables * dim;
      for (int rows : {n / 2 + 1, 2 * n, 5 * n}) {
        for (int nullity : {0, 1, 3}) {
          if (rows < 2 || nullity >= variables * dim) continue;
          Planted p = MakePlanted(rng, variables, dim, rows, nullity);
          const Determinedness d =
              AnalyseDeterminedness(p.jacobian, Ids(variables), Offsets(variables, dim));
          // The truth: a dense SVD of the equilibrated matrix.
          Eigen::MatrixXd J(p.jacobian);
          Eigen::VectorXd norms = J.colwise().norm();
          norms = (norms.array() > 0).select(norms, 1.0);  // untouched columns stay zero
          Eigen::MatrixXd Js = J * norms.cwiseInverse().asDiagonal();
          Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js);
          const Eigen::VectorXd& s = svd.singularValues();
          int rank = 0;
          while (rank < s.size() && s(rank) > 1e-9 * s(0)) ++rank;
          const std::string what = std::to_string(variables) + "x" + std::to_string(dim) +
                                   " rows " + std::to_string(rows) + " nullity " +
                                   std::to_string(nullity);
          EXPECT_EQ(d.rank, rank) << what;
          EXPECT_EQ(d.nullity(), n - rank) << what;
          // The basis found spans null(J D⁻¹): J D⁻¹ N ≈ 0, N orthonormal.
          if (d.nullity() > 0) {
            EXPECT_LT((Js * d.null_space).norm(), 1e-8 * s(0)) << what;
            EXPECT_LT((d.null_space.transpose() * d.null_space -
                       Eigen::MatrixXd::Identity(d.nullity(), d.nullity()))
                          .norm(),
                      1e-8)
                << what;
          }
          // With enough rows, the planted space is found (in original units).
          if (rows >= n && nullity > 0) {
            const Eigen::MatrixXd planted = norms.asDiagonal() * p.null_space;
            Eigen::HouseholderQR<Eigen::MatrixXd> qr(planted);
            const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(n, nullity);
            // Projection of the planted space onto the found one keeps it.
            EXPECT_NEAR((d.null_space.transpose() * q).norm(), std::sqrt(nullity), 1e-7) << what;
            EXPECT_FALSE(d.undetermined.empty()) << what;
          }
          if (rows >= n && nullity == 0) EXPECT_TRUE(d.determined()) << what;
          ++cases;
        }
      }
    }
  }
  EXPECT_GE(cases, 75);
}

// A direction with a small but real singular value (10⁻⁶ of the largest) is
// determined; its σ is large, not infinite.
TEST(Determinedness, WeakButRealDirectionsCountAsDetermined) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(100, 80);
  J(5, 5) = 1e-6;
  // Columns 40 and 41 are equal: only their sum is determined.
  J(40, 41) = 1.0;
  J(41, 40) = 1.0;
  const Sparse Js = J.sparseView();
  std::vector<int> ids, offsets;
  for (int c = 0; c < 80; ++c) ids.push_back(c), offsets.push_back(c);
  const Determinedness d = AnalyseDeterminedness(Js, ids, offsets);
  EXPECT_EQ(d.nullity(), 1);
  ASSERT_EQ(d.undetermined.size(), 2u);
  EXPECT_EQ(d.undetermined[0].variable, 40);
  EXPECT_EQ(d.undetermined[1].variable, 41);
  EXPECT_EQ(d.undetermined[0].moves_with, std::vector<int>{41});
  EXPECT_EQ(d.Find(5), nullptr);
  // The weak column's covariance is 1/(10⁻⁶)² = 10¹², found through the
  // shifted factorisation with refinement.
  const Eigen::MatrixXd c = CovarianceOfDeterminedColumns(Js, d, {5, 6});
  EXPECT_NEAR(c(0, 0), 1e12, 1e12 * 1e-6);
  EXPECT_NEAR(c(1, 1), 1.0, 1e-9);
  EXPECT_NEAR(c(0, 1), 0.0, 1e-6);
}

// y = J x for a linear measurement on R^n variables.
struct Linear {
  Eigen::MatrixXd a, b;  // rows: residuals; columns: variable 1, 2
  Eigen::VectorXd z;
  template <class T>
  bool operator()(T const* const* p, T* r) const {
    const T* x = p[0];
    const T* y = p[1];
    for (int i = 0; i < z.size(); ++i) {
      r[i] = T(-z(i));
      for (int c = 0; c < a.cols(); ++c) r[i] += a(i, c) * x[c];
      for (int c = 0; c < b.cols(); ++c) r[i] += b(i, c) * y[c];
    }
    return true;
  }
};

std::shared_ptr<ceres::CostFunction> MakeLinear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                                const Eigen::VectorXd& z) {
  auto* f = new ceres::DynamicAutoDiffCostFunction<Linear>(new Linear{a, b, z});
  f->AddParameterBlock(static_cast<int>(a.cols()));
  f->AddParameterBlock(static_cast<int>(b.cols()));
  f->SetNumResiduals(static_cast<int>(z.size()));
  return std::shared_ptr<ceres::CostFunction>(f);
}

// The cases: fewer rows than columns fooled Ceres' covariance.
TEST(Determinedness, OneRelativeMeasurementLeavesBothVariablesFree) {
  Problem p;
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  const int a = p.AddVariable(MakeManifold("Rn", 2), zero.data(), "a");
  const int b = p.AddVariable(MakeManifold("Rn", 2), zero.data(), "b");
  p.SetDirectionLabels(b, {"x", "y"});
  p.AddMeasurement(MakeLinear(-2 * Eigen::Matrix2d::Identity(), 2 * Eigen::Matrix2d::Identity(),
                              Eigen::Vector2d(1, 2)),
                   {a, b});
  ASSERT_TRUE(p.Solve().usable);
  const Determinedness& d = p.CheckDetermined();
  EXPECT_EQ(d.rank, 2);
  EXPECT_EQ(d.nullity(), 2);
  ExpectError([&] { p.Covariance(b); },
              "covariance of 'b' is undefined: the measurements do not determine the position "
              "of the whole (a gauge freedom: these variables move together without changing "
              "any residual; fix one or give one a prior): 'a': all 2 directions (tied to 'b'); "
              "'b': all 2 directions (tied to 'a')");
}

TEST(Determinedness, OneScalarSumNamesTheDirectionLeftFree) {
  Problem p;
  const double zero = 0.0;
  const int a = p.AddVariable(MakeManifold("Rn", 1), &zero, "a");
  const int b = p.AddVariable(MakeManifold("Rn", 1), &zero, "b");
  const int c = p.AddVariable(MakeManifold("Rn", 2), Eigen::Vector2d(0, 0).data(), "c");
  p.SetDirectionLabels(c, {"u", "v"});
  p.AddMeasurement(MakeLinear(Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                              Eigen::VectorXd::Ones(1)),
                   {a, b});
  ASSERT_TRUE(p.Solve().usable);
  // Alone, a + b = 1 leaves a - b free, tied together.
  ExpectError([&] { p.Covariance(a); }, "'a': d0 (tied to 'b'); 'b': d0 (tied to 'a')");
  // A prior on a determines both; c is measured along u + v only.
  p.AddMeasurement(MakeLinear(Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Zero(1, 1),
                              Eigen::VectorXd::Zero(1)),
                   {a, b});
  Eigen::MatrixXd uv(1, 2);
  uv << 1, 1;
  p.AddMeasurement(MakeLinear(Eigen::MatrixXd::Zero(1, 1), uv, Eigen::VectorXd::Ones(1)), {a, c});
  ASSERT_TRUE(p.Solve().usable);
  ExpectError([&] { p.Covariance(c); }, "do not determine 'c': 0.71 u - 0.71 v (add measurements");
  // Unit noise: var(a) = 1 from its prior, var(b) = 2, cov(a, b) = -1.
  const Eigen::MatrixXd ab = p.JointCovariance({a, b});
  EXPECT_NEAR(ab(0, 0), 1.0, 1e-9);
  EXPECT_NEAR(ab(1, 1), 2.0, 1e-9);
  EXPECT_NEAR(ab(0, 1), -1.0, 1e-9);
}

// When part of the problem is free, the determined variables keep their
// covariance: that of the same problem with the free part removed.
TEST(Determinedness, DeterminedVariablesKeepTheirCovarianceBesideFreeOnes) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 10; ++trial) {
    Problem p, alone;
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    const int a = p.AddVariable(MakeManifold("Rn", 3), zero.data(), "a");
    const int b = p.AddVariable(MakeManifold("Rn", 3), zero.data(), "b");
    const int free1 = p.AddVariable(MakeManifold("Rn", 3), zero.data(), "f1");
    const int free2 = p.AddVariable(MakeManifold("Rn", 3), zero.data(), "f2");
    const int a2 = alone.AddVariable(MakeManifold("Rn", 3), zero.data(), "a");
    const int b2 = alone.AddVariable(MakeManifold("Rn", 3), zero.data(), "b");
    for (int k = 0; k < 4; ++k) {
      const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(3, 3, [&] { return g(rng); });
      const Eigen::MatrixXd B = Eigen::MatrixXd::NullaryExpr(3, 3, [&] { return g(rng); });
      const Eigen::VectorXd z = Eigen::VectorXd::NullaryExpr(3, [&] { return g(rng); });
      p.AddMeasurement(MakeLinear(A, B, z), {a, b});
      alone.AddMeasurement(MakeLinear(A, B, z), {a2, b2});
    }
    // f1 and f2 are seen only through their difference (a gauge).
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(3, 3);
    p.AddMeasurement(MakeLinear(-I, I, Eigen::VectorXd::Ones(3)), {free1, free2});
    ASSERT_TRUE(p.Solve().usable);
    ASSERT_TRUE(alone.Solve().usable);
    EXPECT_FALSE(p.CheckDetermined().determined());
    EXPECT_TRUE(alone.CheckDetermined().determined());
    const Eigen::MatrixXd want = alone.JointCovariance({a2, b2});
    const Eigen::MatrixXd got = p.JointCovariance({a, b});
    EXPECT_LT((got - want).norm(), 1e-8 * want.norm()) << trial;
    ExpectError([&] { p.Covariance(free2); }, "'f1': all 3 directions (tied to 'f2')");
  }
}

// A chain of poses with relative measurements only: the gauge (all six
// directions, every pose tied to the others) is named; anchoring one pose
// removes it.
TEST(Determinedness, PoseChainWithoutAnchorIsAGauge) {
  Problem p;
  std::vector<int> ids;
  const SE3 start;
  for (int k = 0; k < 30; ++k) {
    ids.push_back(p.AddVariable(MakeManifold("SE3"), start.data(), "x" + std::to_string(k)));
  }
  for (int k = 0; k + 1 < 30; ++k) {
    const SE3 z(SO3::Exp(Eigen::Vector3d(0.01 * k, 0.1, 0.0)), Eigen::Vector3d(1, 0, 0.1 * k));
    p.AddMeasurement(MakeRelativePose3D(z.ambient(), NoiseModel::Unit(6)), {ids[k], ids[k + 1]});
  }
  ASSERT_TRUE(p.Solve().usable);
  const Determinedness& d = p.CheckDetermined();
  EXPECT_EQ(d.nullity(), 6);
  EXPECT_EQ(d.undetermined.size(), 30u);
  ExpectError([&] { p.Covariance(ids[3]); },
              "(a gauge freedom: these variables move together without changing any residual; "
              "fix one or give one a prior): 'x0': all 6 directions (tied to 'x1', 'x2', 'x3' "
              "and 26 more)");
  // 30 variables: eight are named, the rest counted
  ExpectError([&] { p.Covariance(ids[3]); },
              "'x7': all 6 directions (tied to 'x0', 'x1', 'x2' and 26 more); and 22 more "
              "variables (add");
  p.SetFixed(ids[0]);
  EXPECT_TRUE(p.CheckDetermined().determined());
  EXPECT_EQ(p.Covariance(ids[3]).rows(), 6);
}

}  // namespace
}  // namespace boxplus
