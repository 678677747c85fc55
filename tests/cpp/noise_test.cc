// Tests of NoiseModel::Information and the reader's positive-definiteness
// check at every size: the pose-graph sizes (2, 3, 6) take fixed-size,
// unrolled code and every other size the dynamic one; both must agree.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "boxplus/errors.h"
#include "boxplus/io/g2o.h"
#include "boxplus/noise.h"

namespace boxplus {
namespace {

Eigen::MatrixXd RandomSpd(int n, std::mt19937* rng, double condition) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(*rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd Q = qr.householderQ();
  Eigen::VectorXd eig = Eigen::VectorXd::LinSpaced(n, 0.0, std::log10(condition));
  eig = eig.unaryExpr([](double e) { return std::pow(10.0, e); });
  const Eigen::MatrixXd S = Q * eig.asDiagonal() * Q.transpose();
  return 0.5 * (S + S.transpose());
}

TEST(NoiseInformation, FactorsAnyInformationAsUpperTriangularSquareRoot) {
  std::mt19937 rng(7);
  for (int n = 1; n <= 7; ++n) {
    for (double condition : {1.0, 1e3, 1e9}) {
      const Eigen::MatrixXd info = RandomSpd(n, &rng, condition);
      const NoiseModel noise = NoiseModel::Information(info);
      const Eigen::MatrixXd& W = noise.sqrt_information();
      ASSERT_EQ(W.rows(), n);
      EXPECT_TRUE(W.isUpperTriangular(0.0)) << "n = " << n;
      EXPECT_TRUE(W.diagonal().minCoeff() > 0) << "n = " << n;
      EXPECT_LE((W.transpose() * W - info).norm(), 1e-12 * info.norm()) << "n = " << n;
      // The same factor as the dynamic-size Cholesky gives (unique for SPD Ω).
      const Eigen::MatrixXd U = Eigen::LLT<Eigen::MatrixXd>(info).matrixU();
      EXPECT_LE((W - U).norm(), 1e-12 * U.norm()) << "n = " << n;
      EXPECT_TRUE(io::IsPositiveDefinite(info)) << "n = " << n;
    }
  }
}

TEST(NoiseInformation, RefusesWhatIsNotAnInformationMatrixAtEverySize) {
  std::mt19937 rng(11);
  for (int n = 1; n <= 7; ++n) {
    const Eigen::MatrixXd info = RandomSpd(n, &rng, 10.0);
    EXPECT_THROW(NoiseModel::Information(-info), Error) << "n = " << n;
    EXPECT_FALSE(io::IsPositiveDefinite(-info)) << "n = " << n;
    Eigen::MatrixXd nan = info;
    nan(n - 1, 0) = nan(0, n - 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(NoiseModel::Information(nan), Error) << "n = " << n;
    EXPECT_FALSE(io::IsPositiveDefinite(nan)) << "n = " << n;
    Eigen::MatrixXd semi = info;  // a zero eigenvalue: positive semi-definite only
    semi.row(n - 1).setZero();
    semi.col(n - 1).setZero();
    EXPECT_THROW(NoiseModel::Information(semi), Error) << "n = " << n;
    EXPECT_FALSE(io::IsPositiveDefinite(semi)) << "n = " << n;
    if (n > 1) {
      Eigen::MatrixXd asym = info;
      asym(0, n - 1) += 1.0;
      EXPECT_THROW(NoiseModel::Information(asym), Error) << "n = " << n;
    }
  }
  EXPECT_THROW(NoiseModel::Information(Eigen::MatrixXd(2, 3)), Error);
  EXPECT_FALSE(io::IsPositiveDefinite(Eigen::MatrixXd(2, 3)));
  EXPECT_FALSE(io::IsPositiveDefinite(Eigen::MatrixXd(0, 0)));
}

TEST(NoiseInformation, RefusesANumericallySingularInformationAtEverySize) {
  // Ω = LLᵀ with L = [[s, 0], [1, s]] (s = 1e-155) in the last two rows of an
  // identity: exactly, L⁻¹ has the entry −1/s² ≈ −1e310, so un-whitening would
  // overflow; in floating point 1 + s² rounds to 1 and the factorisation
  // itself fails. Either way the model is refused, naming what it was for.
  for (int n = 2; n <= 7; ++n) {
    const double s = 1e-155;
    Eigen::MatrixXd L = Eigen::MatrixXd::Identity(n, n);
    L(n - 2, n - 2) = L(n - 1, n - 1) = s;
    L(n - 1, n - 2) = 1.0;
    const Eigen::MatrixXd info = L * L.transpose();
    ASSERT_TRUE(info.allFinite());
    try {
      NoiseModel::Information(info, "edge 4");
      ADD_FAILURE() << "accepted at n = " << n;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("edge 4: information matrix is"), std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(io::IsPositiveDefinite(info)) << "n = " << n;
  }
}

}  // namespace
}  // namespace boxplus
