// Tests of the assembled normal equations H = Σ w JᵀJ, g = Σ w Jᵀr against
// a dense reference whose tangent Jacobians are central differences of
// r(x ⊞ δ): SE(2) and SE(3) relative-pose terms (the fixed-size path),
// priors, terms touching a fixed block, a Euclidean block and a robust loss
// (the general path), in one problem, serially and on two threads.
#include <memory>
#include <random>
#include <vector>

#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "../../cpp/src/solver/normal_equations.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/manifolds.h"
#include "boxplus/noise.h"

namespace boxplus::internal {
namespace {

struct TestProblem {
  std::vector<std::vector<double>> values;
  std::vector<std::shared_ptr<const ceres::Manifold>> manifolds;
  std::vector<std::shared_ptr<ceres::CostFunction>> costs;
  std::shared_ptr<ceres::LossFunction> loss = std::make_shared<ceres::CauchyLoss>(0.7);
  std::vector<LsqBlock> blocks;
  std::vector<LsqTerm> terms;
};

Eigen::MatrixXd RandomInformation(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(*rng);
  return A * A.transpose() + n * Eigen::MatrixXd::Identity(n, n);
}

// Two chains, 2D and 3D, each with loop closures, priors and a fixed first pose.
TestProblem MakeProblem(std::mt19937* rng, PoseErrorConvention conv) {
  std::normal_distribution<double> normal;
  TestProblem p;
  const auto se2 = MakeManifold("SE2");
  const auto se3 = MakeManifold("SE3");
  const auto r3 = MakeManifold("Rn", 3);
  auto add_block = [&](std::shared_ptr<const ceres::Manifold> m, std::vector<double> x) {
    p.values.push_back(std::move(x));
    p.manifolds.push_back(std::move(m));
  };
  const int n = 6;
  for (int i = 0; i < n; ++i) add_block(se2, {normal(*rng), normal(*rng), normal(*rng)});
  for (int i = 0; i < n; ++i) {
    const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
    add_block(se3, {normal(*rng), normal(*rng), normal(*rng), q.x(), q.y(), q.z(), q.w()});
  }
  add_block(r3, {normal(*rng), normal(*rng), normal(*rng)});  // Euclidean
  const int landmark = 2 * n;
  struct Use {
    std::shared_ptr<ceres::CostFunction> cost;
    std::vector<int> blocks;
    bool robust;
  };
  std::vector<Use> uses;
  for (int i = 0; i < n; ++i) {
    for (int j : {i + 1, i + 3}) {
      if (j >= n) continue;
      const Eigen::Vector3d z(normal(*rng), normal(*rng), normal(*rng));
      uses.push_back(
          {MakeRelativePose2D(z, NoiseModel::Information(RandomInformation(3, rng)), conv),
           {i, j},
           (i + j) % 3 == 0});
      Eigen::Matrix<double, 7, 1> z3;
      const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
      z3 << normal(*rng), normal(*rng), normal(*rng), q.x(), q.y(), q.z(), q.w();
      uses.push_back(
          {MakeRelativePose3D(z3, NoiseModel::Information(RandomInformation(6, rng)), conv),
           {n + j, n + i},  // arguments in the other order than the columns
           (i + j) % 2 == 0});
    }
  }
  uses.push_back({MakePrior(*se3, Eigen::Map<const Eigen::VectorXd>(p.values[n + 2].data(), 7),
                            NoiseModel::Information(RandomInformation(6, rng)), "prior"),
                  {n + 2},
                  false});
  // A relative pose to the fixed block 0 (general path: one free block).
  uses.push_back({MakeRelativePose2D(Eigen::Vector3d(1, 0, 0.1),
                                     NoiseModel::Information(RandomInformation(3, rng)), conv),
                  {0, 4},
                  false});
  uses.push_back({MakePrior(*r3, Eigen::Map<const Eigen::VectorXd>(p.values[landmark].data(), 3),
                            NoiseModel::Information(RandomInformation(3, rng)), "landmark"),
                  {landmark},
                  true});
  for (size_t b = 0; b < p.values.size(); ++b) {
    const bool fixed = b == 0 || b == static_cast<size_t>(n);
    p.blocks.push_back(
        {p.values[b].data(), p.manifolds[b].get(), fixed, b == static_cast<size_t>(landmark)});
  }
  for (Use& u : uses) {
    p.costs.push_back(u.cost);
    p.terms.push_back({u.cost.get(), u.robust ? p.loss.get() : nullptr, u.blocks});
  }
  return p;
}

// Dense H and g over the free blocks in the given column layout, from central
// differences of each term's residual at x ⊞ δ.
void Reference(const TestProblem& p, const NormalEquations& ne, Eigen::MatrixXd* H,
               Eigen::VectorXd* g, double* cost) {
  const int N = ne.tangent_size();
  *H = Eigen::MatrixXd::Zero(N, N);
  *g = Eigen::VectorXd::Zero(N);
  *cost = 0.0;
  std::vector<int> free_of(p.blocks.size(), -1);
  for (size_t f = 0; f < ne.free_blocks().size(); ++f) free_of[ne.free_blocks()[f]] = f;
  for (const LsqTerm& term : p.terms) {
    const int nr = term.cost->num_residuals();
    std::vector<std::vector<double>> x;
    for (int b : term.blocks) x.push_back(p.values[b]);
    auto residual = [&](const std::vector<std::vector<double>>& at) {
      std::vector<const double*> ptrs;
      for (const auto& v : at) ptrs.push_back(v.data());
      Eigen::VectorXd r(nr);
      EXPECT_TRUE(term.cost->Evaluate(ptrs.data(), r.data(), nullptr));
      return r;
    };
    const Eigen::VectorXd r = residual(x);
    double rho[3] = {r.squaredNorm(), 1.0, 0.0};
    if (term.loss) term.loss->Evaluate(r.squaredNorm(), rho);
    *cost += 0.5 * rho[0];
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(nr, N);
    for (size_t k = 0; k < term.blocks.size(); ++k) {
      const int f = free_of[term.blocks[k]];
      if (f < 0) continue;
      const ceres::Manifold& m = *p.blocks[term.blocks[k]].manifold;
      for (int d = 0; d < m.TangentSize(); ++d) {
        const double h = 1e-6;
        Eigen::VectorXd delta = Eigen::VectorXd::Zero(m.TangentSize());
        auto at = x;
        delta[d] = h;
        m.Plus(x[k].data(), delta.data(), at[k].data());
        const Eigen::VectorXd rp = residual(at);
        delta[d] = -h;
        m.Plus(x[k].data(), delta.data(), at[k].data());
        const Eigen::VectorXd rm = residual(at);
        J.col(ne.column(f) + d) = (rp - rm) / (2 * h);
      }
    }
    *H += rho[1] * J.transpose() * J;
    *g += rho[1] * J.transpose() * r;
  }
}

TEST(NormalEquations, AssembleMatchesCentralDifferencesOnMixedTerms) {
  for (auto conv : {PoseErrorConvention::kG2o, PoseErrorConvention::kLog}) {
    for (int threads : {1, 2}) {
      std::mt19937 rng(3);
      const TestProblem p = MakeProblem(&rng, conv);
      NormalEquations ne(p.blocks, p.terms, threads);
      double cost = 0;
      ASSERT_TRUE(ne.Assemble(&cost));
      Eigen::MatrixXd H_ref;
      Eigen::VectorXd g_ref;
      double cost_ref = 0;
      Reference(p, ne, &H_ref, &g_ref, &cost_ref);
      const Eigen::MatrixXd upper = Eigen::MatrixXd(ne.hessian());
      const Eigen::MatrixXd H = upper.selfadjointView<Eigen::Upper>();
      EXPECT_NEAR(cost, cost_ref, 1e-12 * cost_ref);
      EXPECT_LE((H - H_ref).norm(), 1e-6 * H_ref.norm())
          << "convention " << static_cast<int>(conv) << ", threads " << threads;
      EXPECT_LE((ne.gradient() - g_ref).norm(), 1e-6 * g_ref.norm())
          << "convention " << static_cast<int>(conv) << ", threads " << threads;
    }
  }
}

}  // namespace
}  // namespace boxplus::internal
