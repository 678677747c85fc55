// boxplus::NoiseModel — the one description of a measurement's noise.
//
// A measurement (z, Σ, f, Y) has the error e = f(Y) ⊟ z and the whitened
// residual r = W e with WᵀW = Ω = Σ⁻¹, so that r has unit covariance and
// ½‖r‖² = ½ eᵀΩe (Hertzberg et al. 2013, Sec. 4; the MTKM paper's residual
// L⁻¹(f(Y) ⊟ z) with LLᵀ = Σ is W = L⁻¹). Any W with WᵀW = Ω gives the same
// cost; the one kept here is
//   from σ (a vector)        W = diag(1/σᵢ)
//   from Σ                   W = L⁻¹, LLᵀ = Σ (lower Cholesky factor)
//   from Ω                   W = U,   UᵀU = Ω (upper Cholesky factor)
//   from a square root W     W itself (must be invertible)
// A NoiseModel of dimension d also whitens an error of k·d entries block by
// block with the same W (a board of N corners: d = 2, 2N residuals).
//
// Every factor factory takes a NoiseModel; the factor whitens with
// WhitenInPlace/Whiten below (templated, so autodiff Jets pass through), and
// boxplus::Problem keeps each measurement's NoiseModel so that errors are
// un-whitened in one place (Problem::Error). The idea is GTSAM's NoiseModel
// (noiseModel::Gaussian::Covariance/Information/SqrtInformation/Sigmas).
#pragma once

#include <string>

#include <Eigen/Core>

#include "boxplus/errors.h"

namespace boxplus {

class NoiseModel {
 public:
  // How the model was given (kept for reprs and for writing files back).
  enum class Form { kUnit, kSigmas, kCovariance, kInformation, kSqrtInformation };

  // Unit noise of dimension 0: the residual is the error. Only for
  // measurements whose whitening is not a matrix (SE-Sync's precisions).
  NoiseModel() = default;

  // Each constructor validates its input and throws boxplus::Error naming
  // `what` (the measurement) when it is not a valid noise description.
  static NoiseModel Unit(int dim);
  static NoiseModel Isotropic(int dim, double sigma, const std::string& what = "noise");
  static NoiseModel Sigmas(const Eigen::VectorXd& sigmas, const std::string& what = "noise");
  static NoiseModel Covariance(const Eigen::MatrixXd& covariance,
                               const std::string& what = "noise");
  static NoiseModel Information(const Eigen::MatrixXd& information,
                                const std::string& what = "noise");
  static NoiseModel SqrtInformation(const Eigen::MatrixXd& sqrt_information,
                                    const std::string& what = "noise");

  int dim() const { return static_cast<int>(W_.rows()); }
  Form form() const { return form_; }
  // True when W is the identity (Unit, or σ = 1 everywhere).
  bool is_unit() const { return unit_; }

  // W (dim × dim): r = W e.
  const Eigen::MatrixXd& sqrt_information() const { return W_; }
  // W⁻¹ (dim × dim): e = W⁻¹ r.
  const Eigen::MatrixXd& inverse_sqrt_information() const { return W_inv_; }
  Eigen::MatrixXd information() const { return W_.transpose() * W_; }
  Eigen::MatrixXd covariance() const { return W_inv_ * W_inv_.transpose(); }
  // √diag(Σ): the marginal standard deviation of each error coordinate.
  Eigen::VectorXd sigmas() const;

  // W as a fixed-size matrix for a factor's functor; throws unless dim() == N.
  template <int N>
  Eigen::Matrix<double, N, N> Fixed(const std::string& what) const {
    BOXPLUS_CHECK(dim() == N, what, ": noise of dimension ", dim(), " for an error of ", N,
                  " entries");
    return W_;
  }

  // r = W e and e = W⁻¹ r for e, r of k·dim() entries (block-diagonal).
  Eigen::VectorXd Whiten(const Eigen::VectorXd& e) const;
  Eigen::VectorXd Unwhiten(const Eigen::VectorXd& r) const;

  // One line, e.g. "NoiseModel.sigmas([0.5, 0.5])" or "NoiseModel.covariance(3×3)".
  std::string Describe() const;

 private:
  NoiseModel(Form form, Eigen::MatrixXd W, Eigen::MatrixXd W_inv);
  Form form_ = Form::kUnit;
  Eigen::MatrixXd W_ = Eigen::MatrixXd(0, 0);
  Eigen::MatrixXd W_inv_ = Eigen::MatrixXd(0, 0);
  bool unit_ = true;
};

// r = W e for one block of N entries, any scalar type (double or ceres::Jet).
// The one whitening kernel every factor uses.
template <int N, typename T>
void Whiten(const Eigen::Matrix<double, N, N>& W, const T* e, T* r) {
  for (int i = 0; i < N; ++i) {
    T s = T(0.0);
    for (int j = 0; j < N; ++j) s += W(i, j) * e[j];
    r[i] = s;
  }
}

// e ← W e in place (the error is computed into the residual buffer first).
template <int N, typename T>
void WhitenInPlace(const Eigen::Matrix<double, N, N>& W, T* e) {
  T tmp[N];
  for (int i = 0; i < N; ++i) tmp[i] = e[i];
  Whiten<N>(W, tmp, e);
}

}  // namespace boxplus
