// Riemannian Newton steps on SE-Sync's objective f(X) = tr(X M Xᵀ), X = [t |
// Y₁ … Yₙ], Yᵢ ∈ St(d, r): the accuracy a certificate needs.
//
// The certificate's rounding terms grow with the residual E = S Xᵀ (half the
// Riemannian gradient, certify/certificate.h); Gauss–Newton and Levenberg–
// Marquardt converge only linearly on these large-residual problems, and
// their line searches stop where f no longer resolves the decrease (about
// ‖grad f‖ ~ 10⁻⁶ on MIT). Newton's model uses the exact Riemannian Hessian
// Hess f(X)[Ẋ] = 2 P_X(Ẋ S) (Rosen et al., IJRR 2019, Eq. 33), i.e.
//   f(R_X(Ẋ)) ≈ f(X) + tr((X + Ẋ) S (X + Ẋ)ᵀ) − tr(X S Xᵀ),
// minimised over tangent Ẋ (translations free but the anchor's, rotation
// blocks Ẏᵢ = Bᵢδᵢ in the Stiefel basis, the anchor's rotation held): one
// sparse solve per step, quadratic convergence near a strict local minimum.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "boxplus/certify/certificate.h"

namespace boxplus::certify::internal {

// Up to `max_steps` Newton steps from X, each kept only if it reduces ‖E‖
// without raising f beyond rounding; returns the number kept.
int NewtonPolish(const SESyncGraph& graph, const Eigen::SparseMatrix<double>& M, Eigen::MatrixXd* X,
                 int max_steps = 5);

}  // namespace boxplus::certify::internal
