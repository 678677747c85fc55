// The Riemannian staircase of SE-Sync (Rosen et al., IJRR 2019, Alg. 1 and
// Sec. 4.1): when a rank-d critical point is not certified, lift it to rank
// r + 1 along the certificate's eigenvector of λ_min < 0 (a direction of
// second-order descent, Sec. 4.1.2), solve the rank-r relaxation
//   min tr(X M Xᵀ)  over  X = [t | Y₁ … Yₙ],  tᵢ ∈ Rʳ,  Yᵢ ∈ St(d, r)   (Eq. 21)
// to a critical point (Ceres' Levenberg–Marquardt on the Stiefel manifold of
// certify/stiefel_manifold.h; the edge residuals are linear in X), and certify
// it (certify/certificate.h). A certified rank-r point solves the semidefinite
// relaxation: f there is a lower bound on the pose graph's optimum p*. It is
// rounded to SO(d)ⁿ (Alg. 2: the top d singular directions of the rotation
// blocks, the sign that makes most determinants positive, each block projected
// to SO(d)) with the translations optimal for those rotations; the caller
// refines that point locally and certifies it again (certify/certify.h).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "boxplus/certify/certificate.h"

namespace boxplus::certify {

struct StaircaseOptions {
  int max_rank = 10;         // SE-Sync's default r_max
  int max_iterations = 500;  // of each rank's solve
  CertificateOptions certificate;
  // Polled between iterations (Ctrl-C): true stops the staircase where it is.
  std::function<bool()> interrupted;
};

struct StaircaseResult {
  bool relaxation_certified = false;  // the last rank-r point solves the SDP
  int rank = 0;                       // the last rank solved
  double relaxation_objective = 0.0;  // f at the last rank-r point
  // A lower bound on p* (−inf if no rank-r point was certified).
  double lower_bound = 0.0;
  Eigen::MatrixXd rounded;                // d × (n + dn): rounded to SO(d)ⁿ
  std::vector<Certificate> certificates;  // of each lifted rank
  int iterations = 0;
  bool interrupted = false;
  double time_s = 0.0;
};

// X: a rank-d critical point; its certificate `first` (not certified, with
// its eigenvector).
StaircaseResult RiemannianStaircase(const SESyncGraph& graph, const Eigen::SparseMatrix<double>& M,
                                    const Eigen::MatrixXd& X, const Certificate& first,
                                    const StaircaseOptions& options = {});

// Rounds a rank-r point to SO(d)ⁿ with the optimal translations (Alg. 2).
Eigen::MatrixXd RoundSolution(const SESyncGraph& graph, const Eigen::SparseMatrix<double>& M,
                              const Eigen::MatrixXd& Y);

}  // namespace boxplus::certify
