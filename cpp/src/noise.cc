#include "boxplus/noise.h"

#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace boxplus {

namespace {

void CheckSquareFinite(const Eigen::MatrixXd& m, const std::string& what, const char* kind) {
  BOXPLUS_CHECK(m.rows() == m.cols() && m.rows() > 0, what, ": ", kind,
                " must be a non-empty square matrix, got ", m.rows(), "×", m.cols());
  BOXPLUS_CHECK(m.allFinite(), what, ": ", kind, " has non-finite entries");
}

void CheckSymmetric(const Eigen::MatrixXd& m, const std::string& what, const char* kind) {
  const double scale = std::max(1.0, m.cwiseAbs().maxCoeff());
  BOXPLUS_CHECK((m - m.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale, what, ": ", kind,
                " is not symmetric");
}

// Lower Cholesky factor of an SPD matrix, or a named error.
Eigen::MatrixXd CholeskyLower(const Eigen::MatrixXd& m, const std::string& what, const char* kind) {
  CheckSquareFinite(m, what, kind);
  CheckSymmetric(m, what, kind);
  Eigen::LLT<Eigen::MatrixXd> llt(m);
  BOXPLUS_CHECK(llt.info() == Eigen::Success, what, ": ", kind, " is not positive definite");
  Eigen::MatrixXd L = llt.matrixL();
  BOXPLUS_CHECK(L.diagonal().minCoeff() > 0 && L.allFinite(), what, ": ", kind,
                " is not positive definite");
  return L;
}

Eigen::MatrixXd LowerInverse(const Eigen::MatrixXd& L) {
  return L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(L.rows(), L.rows()));
}

}  // namespace

NoiseModel::NoiseModel(Form form, Eigen::MatrixXd W, Eigen::MatrixXd W_inv)
    : form_(form), W_(std::move(W)), W_inv_(std::move(W_inv)) {
  unit_ = W_.isIdentity(0.0);
}

NoiseModel NoiseModel::Unit(int dim) {
  BOXPLUS_CHECK(dim >= 0, "noise: dimension must be >= 0, got ", dim);
  return NoiseModel(Form::kUnit, Eigen::MatrixXd::Identity(dim, dim),
                    Eigen::MatrixXd::Identity(dim, dim));
}

NoiseModel NoiseModel::Isotropic(int dim, double sigma, const std::string& what) {
  BOXPLUS_CHECK(dim > 0, what, ": noise dimension must be > 0, got ", dim);
  return Sigmas(Eigen::VectorXd::Constant(dim, sigma), what);
}

NoiseModel NoiseModel::Sigmas(const Eigen::VectorXd& sigmas, const std::string& what) {
  BOXPLUS_CHECK(sigmas.size() > 0, what, ": no standard deviations given");
  for (Eigen::Index i = 0; i < sigmas.size(); ++i) {
    BOXPLUS_CHECK(std::isfinite(sigmas[i]) && sigmas[i] > 0, what,
                  ": standard deviations must be positive and finite, got σ[", i,
                  "] = ", sigmas[i]);
  }
  const Eigen::VectorXd w = sigmas.cwiseInverse();
  BOXPLUS_CHECK(w.allFinite(), what, ": a standard deviation is too small (1/σ overflows)");
  return NoiseModel(Form::kSigmas, w.asDiagonal(), sigmas.asDiagonal());
}

NoiseModel NoiseModel::Covariance(const Eigen::MatrixXd& covariance, const std::string& what) {
  const Eigen::MatrixXd L = CholeskyLower(covariance, what, "covariance");
  Eigen::MatrixXd W = LowerInverse(L);
  BOXPLUS_CHECK(W.allFinite(), what, ": covariance is numerically singular");
  return NoiseModel(Form::kCovariance, std::move(W), L);
}

NoiseModel NoiseModel::Information(const Eigen::MatrixXd& information, const std::string& what) {
  const Eigen::MatrixXd L = CholeskyLower(information, what, "information matrix");
  Eigen::MatrixXd U = L.transpose();  // UᵀU = LLᵀ = Ω
  Eigen::MatrixXd U_inv = LowerInverse(L).transpose();
  BOXPLUS_CHECK(U_inv.allFinite(), what, ": information matrix is numerically singular");
  return NoiseModel(Form::kInformation, std::move(U), std::move(U_inv));
}

NoiseModel NoiseModel::SqrtInformation(const Eigen::MatrixXd& sqrt_information,
                                       const std::string& what) {
  CheckSquareFinite(sqrt_information, what, "square-root information");
  Eigen::FullPivLU<Eigen::MatrixXd> lu(sqrt_information);
  BOXPLUS_CHECK(lu.isInvertible(), what, ": square-root information is singular");
  Eigen::MatrixXd inv = lu.inverse();
  BOXPLUS_CHECK(inv.allFinite(), what, ": square-root information is numerically singular");
  return NoiseModel(Form::kSqrtInformation, sqrt_information, std::move(inv));
}

Eigen::VectorXd NoiseModel::sigmas() const {
  return W_inv_.rowwise().norm();  // √diag(W⁻¹W⁻ᵀ)
}

namespace {
Eigen::VectorXd ApplyBlocks(const Eigen::MatrixXd& M, const Eigen::VectorXd& v, const char* op) {
  const Eigen::Index d = M.rows();
  BOXPLUS_CHECK(d > 0 && v.size() % d == 0, "noise: cannot ", op, " a vector of ", v.size(),
                " entries with a noise model of dimension ", d);
  Eigen::VectorXd out(v.size());
  for (Eigen::Index k = 0; k < v.size(); k += d) out.segment(k, d) = M * v.segment(k, d);
  return out;
}
}  // namespace

Eigen::VectorXd NoiseModel::Whiten(const Eigen::VectorXd& e) const {
  return ApplyBlocks(W_, e, "whiten");
}

Eigen::VectorXd NoiseModel::Unwhiten(const Eigen::VectorXd& r) const {
  return ApplyBlocks(W_inv_, r, "un-whiten");
}

std::string NoiseModel::Describe() const {
  std::ostringstream out;
  out.precision(6);
  switch (form_) {
    case Form::kUnit:
      out << "NoiseModel.unit(" << dim() << ")";
      break;
    case Form::kSigmas: {
      out << "NoiseModel.sigmas([";
      const Eigen::VectorXd s = sigmas();
      for (Eigen::Index i = 0; i < s.size(); ++i) out << (i ? ", " : "") << s[i];
      out << "])";
      break;
    }
    case Form::kCovariance:
      out << "NoiseModel.covariance(" << dim() << "×" << dim() << ")";
      break;
    case Form::kInformation:
      out << "NoiseModel.information(" << dim() << "×" << dim() << ")";
      break;
    case Form::kSqrtInformation:
      out << "NoiseModel.sqrt_information(" << dim() << "×" << dim() << ")";
      break;
  }
  return out.str();
}

}  // namespace boxplus
