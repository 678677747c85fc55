// Property tests of every manifold: the four ⊞-axioms over many seeded random
// samples and a catalogue of near-singular ones, analytic Jacobians against
// numeric differences (Ceres' own invariant suite) and against autodiff Jets.
#include <random>

#include <ceres/jet.h>
#include <ceres/manifold_test_utils.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boxplus/manifolds.h"

namespace boxplus {
namespace {

using Vec = Eigen::VectorXd;
// Names EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD expects unqualified.
using ceres::HasCorrectMinusJacobianAt;
using ceres::HasCorrectPlusJacobianAt;
using ceres::HasCorrectRightMultiplyByPlusJacobianAt;
using ceres::MinusPlusIsIdentityAt;
using ceres::MinusPlusJacobianIsIdentityAt;
using ceres::PlusMinusIsIdentityAt;
using ceres::Vector;
using ceres::XMinusXIsZeroAt;
using ceres::XPlusZeroIsXAt;
constexpr double kPiMinus = kPi - 1e-6;  // just inside the injectivity radius

// How to sample points and compare them, per manifold.
template <class Ops>
struct Traits;

Vec RandomUnit(std::mt19937& rng, int n) {
  std::normal_distribution<double> g;
  Vec v(n);
  for (int i = 0; i < n; ++i) v[i] = g(rng);
  return v / v.norm();
}

template <>
struct Traits<SO2Ops> {
  static Vec Point(std::mt19937& rng) {
    return Vec::Constant(1, std::uniform_real_distribution<double>(-kPi, kPi)(rng));
  }
  static std::vector<Vec> Special() {
    return {Vec::Constant(1, 0.0), Vec::Constant(1, kPiMinus), Vec::Constant(1, -kPi),
            Vec::Constant(1, 1e-9)};
  }
  static bool Same(const Vec& a, const Vec& b, double tol) {
    return std::abs(WrapAngle(a[0] - b[0])) < tol;
  }
  static constexpr double kRotRadius = kPi;  // |δ| bound where (x⊞δ)⊟x = δ
};

Vec RandomQuat(std::mt19937& rng) { return RandomUnit(rng, 4); }
std::vector<Vec> SpecialQuats() {
  auto q = [](double x, double y, double z, double w) {
    Vec v(4);
    v << x, y, z, w;
    return v;
  };
  const double c = std::cos(kPiMinus / 2), s = std::sin(kPiMinus / 2);
  return {q(0, 0, 0, 1), q(0, 0, 0, -1), q(1, 0, 0, 0),  // 180° about x
          q(s, 0, 0, c), q(0, s, 0, -c), q(1e-9, 0, 0, 1) / Vec(q(1e-9, 0, 0, 1)).norm()};
}
bool SameQuat(const Vec& a, const Vec& b, double tol) {
  return (a - b).norm() < tol || (a + b).norm() < tol;
}

template <>
struct Traits<SO3Ops> {
  static Vec Point(std::mt19937& rng) { return RandomQuat(rng); }
  static std::vector<Vec> Special() { return SpecialQuats(); }
  static bool Same(const Vec& a, const Vec& b, double tol) { return SameQuat(a, b, tol); }
};

template <>
struct Traits<SE2Ops> {
  static Vec Point(std::mt19937& rng) {
    std::normal_distribution<double> g(0, 10);
    Vec v(3);
    v << g(rng), g(rng), std::uniform_real_distribution<double>(-kPi, kPi)(rng);
    return v;
  }
  static std::vector<Vec> Special() {
    Vec a(3), b(3);
    a << 0, 0, -kPi;
    b << 1e-9, -1e6, kPiMinus;
    return {a, b};
  }
  static bool Same(const Vec& a, const Vec& b, double tol) {
    return (a.head<2>() - b.head<2>()).norm() < tol * std::max(1.0, a.norm()) &&
           std::abs(WrapAngle(a[2] - b[2])) < tol;
  }
};

template <>
struct Traits<SE3Ops> {
  static Vec Point(std::mt19937& rng) {
    std::normal_distribution<double> g(0, 10);
    Vec v(7);
    v << g(rng), g(rng), g(rng), RandomQuat(rng);
    return v;
  }
  static std::vector<Vec> Special() {
    std::vector<Vec> out;
    for (const Vec& q : SpecialQuats()) {
      Vec v(7);
      v << 1e-9, -3, 1e6, q;
      out.push_back(v);
    }
    return out;
  }
  static bool Same(const Vec& a, const Vec& b, double tol) {
    return (a.head<3>() - b.head<3>()).norm() < tol * std::max(1.0, a.head<3>().norm()) &&
           SameQuat(a.tail<4>(), b.tail<4>(), tol);
  }
};

template <>
struct Traits<S2Ops> {
  static Vec Point(std::mt19937& rng) { return RandomUnit(rng, 3); }
  static std::vector<Vec> Special() {
    auto v = [](double x, double y, double z) {
      Vec r(3);
      r << x, y, z;
      return Vec(r / r.norm());
    };
    // the Householder branch switch (x₀ = 0) and both poles of each branch
    return {v(1, 0, 0), v(-1, 0, 0), v(0, 1, 0), v(0, 0, -1), v(1e-12, 1, 0), v(-1e-12, 1, 0)};
  }
  static bool Same(const Vec& a, const Vec& b, double tol) { return (a - b).norm() < tol; }
};

template <>
struct Traits<RnOps<3>> {
  static Vec Point(std::mt19937& rng) {
    std::normal_distribution<double> g(0, 100);
    Vec v(3);
    v << g(rng), g(rng), g(rng);
    return v;
  }
  static std::vector<Vec> Special() { return {Vec::Zero(3)}; }
  static bool Same(const Vec& a, const Vec& b, double tol) {
    return (a - b).norm() < tol * std::max(1.0, a.norm());
  }
};

// The rotational part of δ must stay inside the ball of radius π.
template <class Ops>
Vec RandomDelta(std::mt19937& rng, double max_norm) {
  const double r = std::uniform_real_distribution<double>(0, max_norm)(rng);
  return RandomUnit(rng, Ops::kTangent) * r;
}

template <class Ops>
class ManifoldTest : public ::testing::Test {
 protected:
  OpsManifold<Ops> m;
  std::mt19937 rng{42};
  std::vector<Vec> Points(int n_random) {
    std::vector<Vec> pts = Traits<Ops>::Special();
    for (int i = 0; i < n_random; ++i) pts.push_back(Traits<Ops>::Point(rng));
    return pts;
  }
  std::vector<Vec> Deltas(int n_random) {
    std::vector<Vec> ds;
    ds.push_back(Vec::Zero(Ops::kTangent));
    for (double s : {1e-8, 1e-4, 0.5, kPiMinus}) {
      ds.push_back(RandomUnit(rng, Ops::kTangent) * s);
    }
    for (int i = 0; i < n_random; ++i) ds.push_back(RandomDelta<Ops>(rng, kPiMinus));
    return ds;
  }
  Vec Plus(const Vec& x, const Vec& d) {
    Vec out(Ops::kAmbient);
    Ops::Plus(x.data(), d.data(), out.data());
    return out;
  }
  Vec Minus(const Vec& y, const Vec& x) {
    Vec out(Ops::kTangent);
    Ops::Minus(y.data(), x.data(), out.data());
    return out;
  }
};

using AllOps = ::testing::Types<SO2Ops, SO3Ops, SE2Ops, SE3Ops, S2Ops, RnOps<3>>;
TYPED_TEST_SUITE(ManifoldTest, AllOps);

TYPED_TEST(ManifoldTest, PlusZeroIsIdentity) {
  for (const Vec& x : this->Points(200)) {
    const Vec zero = Vec::Zero(TypeParam::kTangent);
    EXPECT_TRUE(Traits<TypeParam>::Same(this->Plus(x, zero), x, 1e-12)) << x.transpose();
  }
}

TYPED_TEST(ManifoldTest, MinusOfPlusRecoversDelta) {
  const auto pts = this->Points(100);
  for (const Vec& x : pts) {
    for (const Vec& d : this->Deltas(20)) {
      const Vec back = this->Minus(this->Plus(x, d), x);
      EXPECT_LT((back - d).norm(), 1e-9 * std::max(1.0, d.norm()))
          << "x = " << x.transpose() << "\nδ = " << d.transpose()
          << "\n(x⊞δ)⊟x = " << back.transpose();
    }
  }
}

TYPED_TEST(ManifoldTest, PlusOfMinusReachesY) {
  const auto pts = this->Points(100);
  for (const Vec& x : pts) {
    for (const Vec& y : pts) {
      const Vec there = this->Plus(x, this->Minus(y, x));
      EXPECT_TRUE(Traits<TypeParam>::Same(there, y, 1e-9))
          << "x = " << x.transpose() << "\ny = " << y.transpose()
          << "\nx⊞(y⊟x) = " << there.transpose();
    }
  }
}

TYPED_TEST(ManifoldTest, MinusIsNonExpansive) {
  const auto pts = this->Points(50);
  for (const Vec& x : pts) {
    for (int k = 0; k < 20; ++k) {
      // Both δ inside the ball of radius π/2 keeps them on one chart.
      const Vec d1 = RandomDelta<TypeParam>(this->rng, kPi / 2);
      const Vec d2 = RandomDelta<TypeParam>(this->rng, kPi / 2);
      const double lhs = this->Minus(this->Plus(x, d1), this->Plus(x, d2)).norm();
      EXPECT_LE(lhs, (d1 - d2).norm() + 1e-9)
          << "x = " << x.transpose() << "\nδ₁ = " << d1.transpose() << "\nδ₂ = " << d2.transpose();
    }
  }
}

// Ceres' own suite: x⊞0 = x, x⊟x = 0, both inverse laws, Plus/Minus
// Jacobians against Ridders' numeric differences, MinusJac·PlusJac = I.
TYPED_TEST(ManifoldTest, CeresInvariantsHold) {
  // Random points only: Ridders' steps would straddle the ±π seam at the
  // special SO(2) angles (the autodiff test below covers those points).
  std::vector<Vec> pts;
  for (int i = 0; i < 30; ++i) pts.push_back(Traits<TypeParam>::Point(this->rng));
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec& x = pts[i];
    const Vec delta = RandomDelta<TypeParam>(this->rng, 1.0);
    // Choose the representative of y that Plus(x, Minus(y, x)) returns; for
    // quaternions that is the one on x's side (q and −q are one rotation).
    Vec y = this->Plus(x, this->Minus(pts[(i + 1) % pts.size()], x));
    const ceres::Manifold& manifold = this->m;
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-8);
  }
}

// Plus/Minus must compile for Jets, and autodiff through them must give the
// analytic Jacobians (this also exercises the small-angle branches).
TYPED_TEST(ManifoldTest, AutodiffMatchesAnalyticJacobians) {
  constexpr int A = TypeParam::kAmbient, T = TypeParam::kTangent;
  using Jet = ceres::Jet<double, A>;
  using JetT = ceres::Jet<double, T>;
  for (const Vec& x : this->Points(20)) {
    JetT xj[A], dj[T], out[A];
    for (int i = 0; i < A; ++i) xj[i] = JetT(x[i]);
    for (int i = 0; i < T; ++i) dj[i] = JetT(0.0, i);
    TypeParam::Plus(xj, dj, out);
    Eigen::Matrix<double, A, T, Eigen::RowMajor> analytic;
    TypeParam::PlusJacobian(x.data(), analytic.data());
    for (int r = 0; r < A; ++r) {
      EXPECT_LT((out[r].v - analytic.row(r).transpose()).norm(), 1e-12)
          << "PlusJacobian row " << r << " at x = " << x.transpose();
    }
    Jet yj[A], xc[A], mout[T];
    for (int i = 0; i < A; ++i) {
      yj[i] = Jet(x[i], i);
      xc[i] = Jet(x[i]);
    }
    TypeParam::Minus(yj, xc, mout);
    Eigen::Matrix<double, T, A, Eigen::RowMajor> manalytic;
    TypeParam::MinusJacobian(x.data(), manalytic.data());
    for (int r = 0; r < T; ++r) {
      EXPECT_LT((mout[r].v - manalytic.row(r).transpose()).norm(), 1e-9)
          << "MinusJacobian row " << r << " at x = " << x.transpose();
    }
  }
}

TEST(ProductManifold, ActsMemberwiseWithBlockDiagonalJacobians) {
  ProductManifold m({MakeManifold("Rn", 2), MakeManifold("SO3"), MakeManifold("S2")});
  EXPECT_EQ(m.AmbientSize(), 2 + 4 + 3);
  EXPECT_EQ(m.TangentSize(), 2 + 3 + 2);
  std::mt19937 rng(7);
  for (int k = 0; k < 30; ++k) {
    Vec x(9), y(9);
    x << 1.0, -2.0, RandomQuat(rng), RandomUnit(rng, 3);
    y << 3.0, 5.0, RandomQuat(rng), RandomUnit(rng, 3);
    Vec d = RandomUnit(rng, 7) * 0.7;
    Vec ymx(7), back(9);
    ASSERT_TRUE(m.Minus(y.data(), x.data(), ymx.data()));
    ASSERT_TRUE(m.Plus(x.data(), ymx.data(), back.data()));
    y = back;  // representative on x's side, as in CeresInvariantsHold
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(m, x, d, y, 1e-8);
  }
}

TEST(MakeManifold, RejectsUnknownKind) {
  EXPECT_THROW(MakeManifold("SE4"), Error);
  EXPECT_THROW(MakeManifold("Rn", 0), Error);
}

}  // namespace
}  // namespace boxplus
