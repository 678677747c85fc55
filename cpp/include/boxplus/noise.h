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
//
// Only W is stored (a pose graph keeps one model per edge): W⁻¹ is never
// formed for un-whitening, which solves W e = r instead — a division for a
// diagonal W (σ), a triangular solve for the Cholesky forms (W = L⁻¹ is lower,
// W = U upper), an LU solve only for a general square root given by the caller.
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
  // W = diag(w) given directly (positive, finite): exact where 1/σ would
  // round (SE-Sync's √τ, √κ: chordal_relative_pose.h).
  static NoiseModel DiagonalSqrtInformation(const Eigen::VectorXd& w,
                                            const std::string& what = "noise");

  int dim() const { return static_cast<int>(W_.rows()); }
  Form form() const { return form_; }
  // True when W is the identity (Unit, or σ = 1 everywhere).
  bool is_unit() const { return shape_ == Shape::kIdentity; }

  // W (dim × dim): r = W e.
  const Eigen::MatrixXd& sqrt_information() const { return W_; }
  // W⁻¹ (dim × dim), computed on each call (e = W⁻¹ r).
  Eigen::MatrixXd inverse_sqrt_information() const;
  Eigen::MatrixXd information() const { return W_.transpose() * W_; }
  Eigen::MatrixXd covariance() const;
  // √diag(Σ): the marginal standard deviation of each error coordinate.
  Eigen::VectorXd sigmas() const;

  // W as a fixed-size matrix for a factor's functor; throws unless dim() == N.
  template <int N>
  Eigen::Matrix<double, N, N> Fixed(const std::string& what) const {
    BOXPLUS_CHECK(dim() == N, what, ": noise of dimension ", dim(), " for an error of ", N,
                  " entries");
    return W_;
  }

  // r = W e and e = W⁻¹ r for e, r of k·dim() entries (block-diagonal);
  // Unwhiten solves W e = r (see the top of this file).
  Eigen::VectorXd Whiten(const Eigen::VectorXd& e) const;
  Eigen::VectorXd Unwhiten(const Eigen::VectorXd& r) const;

  // One line, e.g. "NoiseModel.sigmas([0.5, 0.5])" or "NoiseModel.covariance(3×3)".
  std::string Describe() const;

 private:
  // The structure of W that Unwhiten exploits, found from W's entries.
  enum class Shape : unsigned char { kIdentity, kDiagonal, kLower, kUpper, kGeneral };
  NoiseModel(Form form, Eigen::MatrixXd W);
  void UnwhitenBlock(Eigen::Ref<Eigen::MatrixXd> B) const;
  Eigen::Index CheckBlocks(Eigen::Index size, const char* op) const;
  Form form_ = Form::kUnit;
  Shape shape_ = Shape::kIdentity;
  Eigen::MatrixXd W_ = Eigen::MatrixXd(0, 0);
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
