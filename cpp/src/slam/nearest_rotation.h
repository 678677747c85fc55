// The rotation nearest to a matrix: the projection onto SO(d) that rounds a
// relaxation's solution (the chordal start, SE-Sync's RoundSolution).
#pragma once

#include <Eigen/Core>
#include <Eigen/SVD>

namespace boxplus::slam {

// argmax tr(RᵀM) over R ∈ SO(d), i.e. the R nearest to M in the Frobenius
// norm (orthogonal Procrustes with the determinant held at +1):
// R = U diag(1, …, 1, sign det(UVᵀ)) Vᵀ for M = U Σ Vᵀ. Fixed-size M (d = 2,
// 3) keeps the SVD on the stack; a dynamic M is d×d at run time.
template <typename Derived>
Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> NearestRotation(
    const Eigen::MatrixBase<Derived>& M) {
  using Square = Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  const Eigen::JacobiSVD<Square> svd(M.eval(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Square S = Square::Identity(M.rows(), M.cols());
  const Eigen::Index last = M.rows() - 1;
  S(last, last) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixU() * S * svd.matrixV().transpose();
}

}  // namespace boxplus::slam
