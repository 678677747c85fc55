// Measurement noise: from a covariance Σ to the whitening matrix L⁻¹
// (LLᵀ = Σ), so that a residual r = L⁻¹(h(x) ⊟ z) has unit covariance.
#pragma once

#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "boxplus/errors.h"

namespace boxplus {

// L⁻¹ for a symmetric positive-definite Σ; `what` names the measurement in
// the error thrown when Σ is not symmetric positive definite.
inline Eigen::MatrixXd SqrtInformationFromCovariance(const Eigen::MatrixXd& sigma,
                                                     const std::string& what) {
  BOXPLUS_CHECK(sigma.rows() == sigma.cols(), what, ": covariance must be square, got ",
                sigma.rows(), "×", sigma.cols());
  BOXPLUS_CHECK(sigma.allFinite(), what, ": covariance has non-finite entries");
  const double scale = std::max(1.0, sigma.cwiseAbs().maxCoeff());
  BOXPLUS_CHECK((sigma - sigma.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale,
                what, ": covariance is not symmetric");
  Eigen::LLT<Eigen::MatrixXd> llt(sigma);
  BOXPLUS_CHECK(llt.info() == Eigen::Success && llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 0,
                what, ": covariance is not positive definite");
  const Eigen::MatrixXd L = llt.matrixL();
  return L.triangularView<Eigen::Lower>().solve(
      Eigen::MatrixXd::Identity(sigma.rows(), sigma.rows()));
}

// Upper-triangular square root U of an information matrix Ω (UᵀU = Ω), the
// whitening that g2o/TORO files imply. Throws unless Ω is SPD.
inline Eigen::MatrixXd SqrtInformationFromInformation(const Eigen::MatrixXd& info,
                                                      const std::string& what) {
  BOXPLUS_CHECK(info.rows() == info.cols() && info.allFinite(), what,
                ": information matrix must be square and finite");
  Eigen::LLT<Eigen::MatrixXd> llt(info);
  BOXPLUS_CHECK(llt.info() == Eigen::Success, what,
                ": information matrix is not positive definite");
  return llt.matrixU();
}

}  // namespace boxplus
