// Sparse Cholesky factorisation of the normal equations H x = b, its method
// chosen once from the symbolic factor; symbolic analysis once, numeric
// factorisation at every solve.
//
// Pose graphs are mostly so sparse that a simplicial LDLᵀ (Eigen's, in the
// block AMD order the matrix arrives in, as g2o uses) beats CHOLMOD's
// supernodal LLᵀ, whose BLAS calls on tiny blocks cost more than they save;
// when the factor fills in, the supernodal one wins. The switch is on the
// fill measure Σ c²/Σ c over the column counts c of L (proportional to the
// factorisation's flops per stored non-zero): 9–52 on the 2D data sets,
// parking-garage and tinyGrid3D, 96 on smallGrid3D, 299 on sphere2500 and 400
// on torus3D; the switch at 150 picked the faster method on each.
//
// The supernodal factor's ordering is the one of least fill among three that
// CHOLMOD tries: the block AMD order H arrives in, AMD on the scalar matrix,
// and METIS' nested dissection. No one of them wins on every graph: against
// scalar AMD alone (CHOLMOD's default here) an iteration took 30 % less on a
// 2D sphere of 10⁴ poses (block AMD and METIS), 12 % less on torus3D and on a
// 3D sphere of 10⁴ poses (METIS), and the same on sphere2500 (AMD); the
// three analyses cost about one iteration, once per solve.
#pragma once

#include <string>

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace boxplus::internal {

// Non-zeros of each column of the Cholesky factor L of the symmetric matrix
// whose upper triangle is `upper` (column-major), strictly below the
// diagonal, in the matrix's own order: the row subtrees of the elimination
// tree (Liu 1990; Davis, "Direct Methods for Sparse Linear Systems", §4.1),
// O(|L|) time.
std::vector<int> CholeskyColumnCounts(const Eigen::SparseMatrix<double>& upper);

// Σ c² / Σ c over the column counts c (0 for a diagonal factor).
double FillMeasure(const std::vector<int>& column_counts);

class SparseCholesky {
 public:
  using Matrix = Eigen::SparseMatrix<double>;
  static constexpr double kSupernodalSwitch = 150.0;

  // Which orderings the supernodal factor tries: the least fill of three
  // (above), or only the order H arrives in (for a caller that ordered it).
  enum class Orderings { kLeastFill, kAsGiven };
  explicit SparseCholesky(Orderings orderings = Orderings::kLeastFill);
  ~SparseCholesky();

  // Chooses the method from the pattern of H (upper triangle) and analyses
  // it; every later H must have this pattern.
  void Analyse(const Matrix& H);
  // x = H⁻¹ b. A singular H (gauge not fixed, a parameter no term
  // determines) is regularised with the smallest shift λI, λ = 10⁻¹² ·
  // max(1, max |Hᵢᵢ|) · 100ᵏ, k < 8, that factorises to a finite x; false
  // when none does.
  bool Solve(const Matrix& H, const Eigen::VectorXd& b, Eigen::VectorXd* x);
  // X = H⁻¹ B for the columns of B at once (one factorisation), without a
  // shift: false when H does not factorise or X is not finite.
  bool SolveUnshifted(const Matrix& H, const Eigen::MatrixXd& B, Eigen::MatrixXd* X);

  // Factorises H + shift·I (shift ≥ 0) once, for several solves with
  // SolveFactorised; false when it does not factorise.
  bool FactoriseShifted(const Matrix& H, double shift) { return Factorise(H, shift); }
  // X = (H + shift·I)⁻¹ B with the last factorisation; false when X is not
  // finite.
  bool SolveFactorised(const Eigen::MatrixXd& B, Eigen::MatrixXd* X);

  bool supernodal() const { return supernodal_; }
  // The method, and for the supernodal one the ordering kept.
  std::string name() const;

 private:
  struct Factors;  // Eigen's and CHOLMOD's, kept out of this header
  bool Factorise(const Matrix& H, double shift);
  template <class Dense>
  bool SolveDense(const Matrix& H, const Dense& b, Dense* x, int attempts);

  std::unique_ptr<Factors> factors_;
  Orderings orderings_;
  bool supernodal_ = false;
};

}  // namespace boxplus::internal
