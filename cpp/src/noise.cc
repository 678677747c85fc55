#include "boxplus/noise.h"

#include <cmath>
#include <sstream>
#include <type_traits>

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
  double asymmetry = 0.0;  // max |mᵢⱼ − mⱼᵢ|, without a temporary matrix
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < j; ++i)
      asymmetry = std::max(asymmetry, std::abs(m(i, j) - m(j, i)));
  }
  BOXPLUS_CHECK(asymmetry <= 1e-9 * scale, what, ": ", kind, " is not symmetric");
}

// Lower Cholesky factor of an SPD matrix, or a named error. Matrix is
// MatrixXd, or a fixed size on the stack for the pose-graph sizes (one model
// per edge of a big graph; a heap matrix per step was most of the model's
// cost). m must be square and, for a fixed Matrix, of its size.
template <class Matrix = Eigen::MatrixXd>
Matrix CholeskyLower(const Eigen::MatrixXd& m, const std::string& what, const char* kind) {
  CheckSquareFinite(m, what, kind);
  CheckSymmetric(m, what, kind);
  const Eigen::LLT<Matrix> llt{Matrix(m)};
  BOXPLUS_CHECK(llt.info() == Eigen::Success, what, ": ", kind, " is not positive definite");
  Matrix L = llt.matrixL();
  BOXPLUS_CHECK(L.diagonal().minCoeff() > 0 && L.allFinite(), what, ": ", kind,
                " is not positive definite");
  return L;
}

template <class Matrix>
Matrix LowerInverse(const Matrix& L) {
  return L.template triangularView<Eigen::Lower>().solve(Matrix::Identity(L.rows(), L.rows()));
}

// L⁻¹ of a fixed-size lower-triangular L by forward substitution, unrolled
// by the compiler. Eigen's solve against a matrix right-hand side takes its
// blocked general kernel (packing and a workspace) even at 3 × 3, which was
// most of a pose graph's model build (one model per edge).
template <int N, std::enable_if_t<(N > 0), int> = 0>
Eigen::Matrix<double, N, N> LowerInverse(const Eigen::Matrix<double, N, N>& L) {
  Eigen::Matrix<double, N, N> X = Eigen::Matrix<double, N, N>::Zero();
  for (int j = 0; j < N; ++j) {
    X(j, j) = 1.0 / L(j, j);
    for (int i = j + 1; i < N; ++i) {
      double s = 0.0;
      for (int k = j; k < i; ++k) s -= L(i, k) * X(k, j);
      X(i, j) = s / L(i, i);
    }
  }
  return X;
}

// UᵀU = LLᵀ = Ω; U⁻¹ is formed only to refuse an Ω whose un-whitening would
// overflow. Matrix is a fixed N × N for the sizes of pose graphs' edges
// (2, 3, 6), else MatrixXd.
template <class Matrix>
Eigen::MatrixXd UpperFactorOfInformation(const Eigen::MatrixXd& information,
                                         const std::string& what) {
  const Matrix L = CholeskyLower<Matrix>(information, what, "information matrix");
  BOXPLUS_CHECK(LowerInverse(L).allFinite(), what, ": information matrix is numerically singular");
  return L.transpose();
}

}  // namespace

NoiseModel::NoiseModel(Form form, Eigen::MatrixXd W) : form_(form), W_(std::move(W)) {
  if (W_.isIdentity(0.0)) {
    shape_ = Shape::kIdentity;
  } else if (W_.isDiagonal(0.0)) {
    shape_ = Shape::kDiagonal;
  } else if (W_.isLowerTriangular(0.0)) {
    shape_ = Shape::kLower;
  } else if (W_.isUpperTriangular(0.0)) {
    shape_ = Shape::kUpper;
  } else {
    shape_ = Shape::kGeneral;
  }
}

NoiseModel NoiseModel::Unit(int dim) {
  BOXPLUS_CHECK(dim >= 0, "noise: dimension must be >= 0, got ", dim);
  return NoiseModel(Form::kUnit, Eigen::MatrixXd::Identity(dim, dim));
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
  return NoiseModel(Form::kSigmas, w.asDiagonal());
}

NoiseModel NoiseModel::Covariance(const Eigen::MatrixXd& covariance, const std::string& what) {
  const Eigen::MatrixXd L = CholeskyLower(covariance, what, "covariance");
  Eigen::MatrixXd W = LowerInverse(L);
  BOXPLUS_CHECK(W.allFinite(), what, ": covariance is numerically singular");
  return NoiseModel(Form::kCovariance, std::move(W));
}

NoiseModel NoiseModel::Information(const Eigen::MatrixXd& information, const std::string& what) {
  const auto factor = [&]() -> Eigen::MatrixXd {
    if (information.rows() == information.cols()) {
      switch (information.rows()) {
        case 2:
          return UpperFactorOfInformation<Eigen::Matrix2d>(information, what);
        case 3:
          return UpperFactorOfInformation<Eigen::Matrix3d>(information, what);
        case 6:
          return UpperFactorOfInformation<Eigen::Matrix<double, 6, 6>>(information, what);
        default:
          break;
      }
    }
    return UpperFactorOfInformation<Eigen::MatrixXd>(information, what);
  };
  return NoiseModel(Form::kInformation, factor());
}

NoiseModel NoiseModel::SqrtInformation(const Eigen::MatrixXd& sqrt_information,
                                       const std::string& what) {
  CheckSquareFinite(sqrt_information, what, "square-root information");
  Eigen::FullPivLU<Eigen::MatrixXd> lu(sqrt_information);
  BOXPLUS_CHECK(lu.isInvertible(), what, ": square-root information is singular");
  BOXPLUS_CHECK(lu.inverse().allFinite(), what,
                ": square-root information is numerically singular");
  return NoiseModel(Form::kSqrtInformation, sqrt_information);
}

NoiseModel NoiseModel::DiagonalSqrtInformation(const Eigen::VectorXd& w, const std::string& what) {
  BOXPLUS_CHECK(w.size() > 0, what, ": no square-root information given");
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    BOXPLUS_CHECK(std::isfinite(w[i]) && w[i] > 0, what,
                  ": square-root information must be positive and finite, got w[", i, "] = ", w[i]);
  }
  return NoiseModel(Form::kSqrtInformation, w.asDiagonal());
}

Eigen::VectorXd NoiseModel::sigmas() const {
  return inverse_sqrt_information().rowwise().norm();  // √diag(W⁻¹W⁻ᵀ)
}

Eigen::MatrixXd NoiseModel::covariance() const {
  const Eigen::MatrixXd W_inv = inverse_sqrt_information();
  return W_inv * W_inv.transpose();
}

Eigen::MatrixXd NoiseModel::inverse_sqrt_information() const {
  Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dim(), dim());
  UnwhitenBlock(I);
  return I;
}

// B ← W⁻¹ B for a matrix B of dim() rows, by the cheapest solve W's shape allows.
void NoiseModel::UnwhitenBlock(Eigen::Ref<Eigen::MatrixXd> B) const {
  switch (shape_) {
    case Shape::kIdentity:
      return;
    case Shape::kDiagonal:
      B.array().colwise() /= W_.diagonal().array();
      return;
    case Shape::kLower:
      W_.triangularView<Eigen::Lower>().solveInPlace(B);
      return;
    case Shape::kUpper:
      W_.triangularView<Eigen::Upper>().solveInPlace(B);
      return;
    case Shape::kGeneral:
      B = W_.fullPivLu().solve(B);
      return;
  }
}

Eigen::VectorXd NoiseModel::Whiten(const Eigen::VectorXd& e) const {
  const Eigen::Index d = CheckBlocks(e.size(), "whiten");
  Eigen::VectorXd out(e.size());
  for (Eigen::Index k = 0; k < e.size(); k += d) out.segment(k, d) = W_ * e.segment(k, d);
  return out;
}

Eigen::VectorXd NoiseModel::Unwhiten(const Eigen::VectorXd& r) const {
  const Eigen::Index d = CheckBlocks(r.size(), "un-whiten");
  // The blocks as the columns of a d × k matrix: one solve for all of them.
  Eigen::MatrixXd blocks = Eigen::Map<const Eigen::MatrixXd>(r.data(), d, r.size() / d);
  UnwhitenBlock(blocks);
  return Eigen::Map<const Eigen::VectorXd>(blocks.data(), r.size());
}

Eigen::Index NoiseModel::CheckBlocks(Eigen::Index size, const char* op) const {
  const Eigen::Index d = W_.rows();
  BOXPLUS_CHECK(d > 0 && size % d == 0, "noise: cannot ", op, " a vector of ", size,
                " entries with a noise model of dimension ", d);
  return d;
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
