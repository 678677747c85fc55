#include "stiefel_manifold.h"

#include <Eigen/QR>

#include "boxplus/errors.h"

namespace boxplus::certify::internal {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

StiefelManifold::StiefelManifold(int r, int d) : r_(r), d_(d) {
  BOXPLUS_CHECK(d >= 1 && r >= d, "Stiefel manifold St(d, r) needs r >= d >= 1, got d = ", d,
                ", r = ", r);
}

Eigen::MatrixXd OrthonormalFactor(const Eigen::MatrixXd& A) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(A.rows(), A.cols());
  const Eigen::MatrixXd R = qr.matrixQR().topRows(A.cols()).triangularView<Eigen::Upper>();
  for (int k = 0; k < A.cols(); ++k) {
    if (R(k, k) < 0) Q.col(k) = -Q.col(k);
  }
  return Q;
}

Eigen::MatrixXd StiefelManifold::Basis(const double* x) const {
  const Eigen::Map<const Eigen::MatrixXd> Y(x, r_, d_);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(r_ * d_, TangentSize());
  int k = 0;
  // Y Eₐᵦ, Eₐᵦ = eₐeᵦᵀ − eᵦeₐᵀ: column b of the product is Y.col(a), column a
  // is −Y.col(b).
  for (int a = 0; a < d_; ++a) {
    for (int b = a + 1; b < d_; ++b, ++k) {
      B.block(b * r_, k, r_, 1) = Y.col(a);
      B.block(a * r_, k, r_, 1) = -Y.col(b);
    }
  }
  if (r_ > d_) {
    const Eigen::MatrixXd Ym = Y;
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(Ym);
    const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(r_, r_);
    const Eigen::MatrixXd Yp = Q.rightCols(r_ - d_);
    // Y⊥ eₚ e_cᵀ: column c is Y⊥.col(p).
    for (int c = 0; c < d_; ++c) {
      for (int p = 0; p < r_ - d_; ++p, ++k) B.block(c * r_, k, r_, 1) = Yp.col(p);
    }
  }
  return B;
}

bool StiefelManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::MatrixXd> Y(x, r_, d_);
  const Eigen::Map<const Eigen::VectorXd> dv(delta, TangentSize());
  Eigen::VectorXd v = Basis(x) * dv;
  const Eigen::Map<const Eigen::MatrixXd> xi(v.data(), r_, d_);
  const Eigen::MatrixXd out = OrthonormalFactor(Y + xi);
  if (!out.allFinite()) return false;
  Eigen::Map<Eigen::MatrixXd>(x_plus_delta, r_, d_) = out;
  return true;
}

bool StiefelManifold::PlusJacobian(const double* x, double* jacobian) const {
  // The QR retraction's differential at δ = 0 is the identity on the
  // tangent space, so the Jacobian is the basis.
  Eigen::Map<RowMajor>(jacobian, r_ * d_, TangentSize()) = Basis(x);
  return true;
}

bool StiefelManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Eigen::VectorXd> Z(y, r_ * d_), X(x, r_ * d_);
  // The basis is orthogonal: the Ω columns have norm √2, the K columns 1.
  Eigen::VectorXd dv = Basis(x).transpose() * (Z - X);
  dv.head(d_ * (d_ - 1) / 2) *= 0.5;
  Eigen::Map<Eigen::VectorXd>(y_minus_x, TangentSize()) = dv;
  return true;
}

bool StiefelManifold::MinusJacobian(const double* x, double* jacobian) const {
  RowMajor J = Basis(x).transpose();
  J.topRows(d_ * (d_ - 1) / 2) *= 0.5;
  Eigen::Map<RowMajor>(jacobian, TangentSize(), r_ * d_) = J;
  return true;
}

}  // namespace boxplus::certify::internal
