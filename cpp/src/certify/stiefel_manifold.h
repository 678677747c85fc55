// The Stiefel manifold St(d, r) = {Y ∈ R^{r×d} : YᵀY = I} as a Ceres
// manifold: the rotation blocks of SE-Sync's rank-r relaxation (Rosen et al.,
// IJRR 2019, Sec. 4.1, Eq. 21).
//
// Ambient: Y column by column (r·d numbers). Tangent at Y: ξ = Y Ω + Y⊥ K
// with Ω skew (d(d−1)/2 coordinates, the entries above the diagonal, in
// row order) and K ∈ R^{(r−d)×d} (column by column), where Y⊥ completes Y to
// the orthogonal matrix of its Householder QR; dimension r d − d(d+1)/2.
//   Y ⊞ δ = qf(Y + ξ(δ))   (the QR retraction; qf: the Q factor with a
//                           positive diagonal of R),
//   Z ⊟ Y = ξ⁻¹(P_Y(Z − Y)) (coordinates of the projection onto the tangent
//                           space: exact for the ⊞ axioms to first order,
//                           which is all Ceres uses).
// At r = d, Y⊥ is empty and ⊞ stays in the component of det Y: SO(d).
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>

namespace boxplus::certify::internal {

class StiefelManifold : public ceres::Manifold {
 public:
  StiefelManifold(int r, int d);
  int AmbientSize() const override { return r_ * d_; }
  int TangentSize() const override { return r_ * d_ - d_ * (d_ + 1) / 2; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // The basis B (r·d × tangent) with vec(ξ) = B δ at Y.
  Eigen::MatrixXd Basis(const double* x) const;

 private:
  int r_, d_;
};

// qf(A): the Q factor of A = QR (r × d) with R's diagonal made positive.
Eigen::MatrixXd OrthonormalFactor(const Eigen::MatrixXd& A);

}  // namespace boxplus::certify::internal
