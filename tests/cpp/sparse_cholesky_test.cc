// Tests of the line search's sparse Cholesky: the column counts from the
// elimination tree equal those of a dense factorisation, the fill measure
// picks the factorisation, and a singular matrix is solved with a shift.
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "../../cpp/src/solver/sparse_cholesky.h"

namespace boxplus::internal {
namespace {

using Matrix = Eigen::SparseMatrix<double>;

// A random symmetric positive definite matrix with a random sparsity pattern.
Eigen::MatrixXd RandomSparseSpd(int n, double density, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < i; ++j) {
      if (u(rng) < density) a(i, j) = a(j, i) = u(rng) - 0.5;
    }
    a(i, i) = n;  // diagonally dominant
  }
  return a;
}

Matrix UpperOf(const Eigen::MatrixXd& a) {
  const Eigen::MatrixXd upper = a.triangularView<Eigen::Upper>();
  return upper.sparseView();
}

TEST(SparseCholesky, ColumnCountsMatchADenseFactor) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 5 + trial * 3;
    const Eigen::MatrixXd a = RandomSparseSpd(n, 0.08, rng);
    const Eigen::MatrixXd l = a.llt().matrixL();
    const std::vector<int> counts = CholeskyColumnCounts(UpperOf(a));
    ASSERT_EQ(static_cast<int>(counts.size()), n);
    for (int j = 0; j < n; ++j) {
      int dense = 0;
      for (int i = j + 1; i < n; ++i) dense += l(i, j) != 0.0;
      EXPECT_EQ(counts[j], dense) << "n " << n << " column " << j;
    }
  }
}

TEST(SparseCholesky, FillMeasureOfTridiagonalAndDenseFactors) {
  const int n = 300;
  Eigen::MatrixXd tri = Eigen::MatrixXd::Identity(n, n) * 4.0;
  for (int i = 0; i + 1 < n; ++i) tri(i, i + 1) = tri(i + 1, i) = 1.0;
  // Every column but the last has one entry below the diagonal.
  EXPECT_DOUBLE_EQ(FillMeasure(CholeskyColumnCounts(UpperOf(tri))), 1.0);
  // A dense factor: c = n−1, ..., 0, Σc²/Σc = (2n − 1)/3.
  const Eigen::MatrixXd dense =
      Eigen::MatrixXd::Constant(n, n, 1.0) + n * Eigen::MatrixXd::Identity(n, n);
  EXPECT_DOUBLE_EQ(FillMeasure(CholeskyColumnCounts(UpperOf(dense))), (2.0 * n - 1) / 3);
  EXPECT_EQ(FillMeasure({}), 0.0);

  SparseCholesky sparse, filled;
  sparse.Analyse(UpperOf(tri));
  filled.Analyse(UpperOf(dense));
  EXPECT_FALSE(sparse.supernodal());
  EXPECT_TRUE(filled.supernodal());
  // Both solve their systems.
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  Eigen::VectorXd x;
  ASSERT_TRUE(sparse.Solve(UpperOf(tri), b, &x));
  EXPECT_LT((tri * x - b).norm(), 1e-12);
  ASSERT_TRUE(filled.Solve(UpperOf(dense), b, &x));
  EXPECT_LT((dense * x - b).norm(), 1e-10);
}

// A 5-point Laplacian on a k × k grid in row-major order: the order it
// arrives in has a band of k, so its factor fills in (supernodal), and AMD or
// nested dissection fill far less: the order kept is not the one it came in.
TEST(SparseCholesky, SupernodalFactorKeepsTheOrderingOfLeastFill) {
  const int k = 200, n = k * k;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const int v = i * k + j;
      entries.emplace_back(v, v, 4.1);
      if (j + 1 < k) entries.emplace_back(v, v + 1, -1.0);
      if (i + 1 < k) entries.emplace_back(v, v + k, -1.0);
    }
  }
  Matrix upper(n, n);
  upper.setFromTriplets(entries.begin(), entries.end());
  SparseCholesky cholesky;
  cholesky.Analyse(upper);
  ASSERT_TRUE(cholesky.supernodal()) << FillMeasure(CholeskyColumnCounts(upper));
  EXPECT_EQ(cholesky.name().find("block AMD"), std::string::npos) << cholesky.name();
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  Eigen::VectorXd x;
  ASSERT_TRUE(cholesky.Solve(upper, b, &x));
  const Matrix full = upper.selfadjointView<Eigen::Upper>();
  EXPECT_LT((full * x - b).norm(), 1e-10 * b.norm());

  // Asked to keep the order it came in, it does; several right-hand sides at once.
  SparseCholesky as_given(SparseCholesky::Orderings::kAsGiven);
  as_given.Analyse(upper);
  ASSERT_TRUE(as_given.supernodal());
  EXPECT_NE(as_given.name().find("block AMD"), std::string::npos) << as_given.name();
  Eigen::MatrixXd B(n, 3), X;
  B << b, b.reverse(), Eigen::VectorXd::Ones(n);
  ASSERT_TRUE(as_given.SolveUnshifted(upper, B, &X));
  EXPECT_LT((full * X - B).norm(), 1e-10 * B.norm());
  EXPECT_LT((X.col(0) - x).norm(), 1e-10 * x.norm());
}

// Without the shift a singular matrix is refused, simplicial or supernodal.
TEST(SparseCholesky, UnshiftedSolveRefusesASingularMatrix) {
  for (int n : {2, 400}) {
    // All ones: rank one, and dense (supernodal) at 400.
    const Eigen::MatrixXd ones = Eigen::MatrixXd::Ones(n, n);
    SparseCholesky cholesky;
    cholesky.Analyse(UpperOf(ones));
    EXPECT_EQ(cholesky.supernodal(), n == 400);
    Eigen::MatrixXd X;
    EXPECT_FALSE(cholesky.SolveUnshifted(UpperOf(ones), Eigen::MatrixXd::Ones(n, 2), &X)) << n;
  }
}

// [[1, 1], [1, 1]] is singular; with b in its range the shifted solve
// returns a finite x with H x ≈ b.
TEST(SparseCholesky, SingularMatrixIsShifted) {
  Eigen::MatrixXd h(2, 2);
  h << 1, 1, 1, 1;
  SparseCholesky cholesky;
  cholesky.Analyse(UpperOf(h));
  Eigen::VectorXd x;
  ASSERT_TRUE(cholesky.Solve(UpperOf(h), Eigen::Vector2d(1, 1), &x));
  EXPECT_TRUE(x.allFinite());
  EXPECT_LT((h * x - Eigen::Vector2d(1, 1)).norm(), 1e-6);
}

}  // namespace
}  // namespace boxplus::internal
