// The Gauss–Newton normal equations of a least-squares problem on manifolds,
//   H δ = −g,   H = Σₜ wₜ JₜᵀJₜ,   g = Σₜ wₜ Jₜᵀrₜ,
// with Jₜ = ∂rₜ(x ⊞ δ)/∂δ at δ = 0 (the cost function's ambient Jacobian times
// each block's Plus Jacobian) over the free blocks, and wₜ = ρ'(‖rₜ‖²) the
// iteratively-reweighted-least-squares weight of a robust loss (g is then the
// exact gradient of ½ Σ ρ(‖r‖²)).
//
// The layout is fixed once: the free blocks (not fixed, touched by a term,
// tangent size > 0) are numbered in an AMD order of the block graph (as g2o
// and Ceres order; 36× smaller than the scalar graph of an SE(3) problem, so
// the scalar factorisation keeps its natural order), and the sparsity pattern
// of the upper triangle of H holds whole blocks (i, j), i ≤ j. Each assembly
// only adds every term's block products into their known positions.
//
// With num_threads > 1 the terms are split into that many contiguous ranges,
// evaluated concurrently (cost functions are const and Ceres evaluates them
// concurrently too); each thread adds into its own copy of H's values and g,
// and the copies are summed afterwards. The sums are then taken in another
// order than the serial loop's, so results agree with it to rounding, and are
// the same from run to run for a given number of threads.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "least_squares.h"

namespace boxplus::internal {

class NormalEquations {
 public:
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  // Both lists must outlive this object.
  NormalEquations(const std::vector<LsqBlock>& blocks, const std::vector<LsqTerm>& terms,
                  int num_threads = 1);

  // The free blocks in column order, where each one's tangent coordinates
  // start, and how many there are (in total: tangent_size()).
  const std::vector<int>& free_blocks() const { return free_; }
  int column(int f) const { return col_[f]; }
  int tangent(int f) const { return tangent_[f]; }
  int tangent_size() const { return n_; }

  // ½ Σ ρ(‖r‖²) at the current values; false when a term cannot be evaluated
  // or the cost is not finite.
  bool EvaluateCost(double* cost);
  // The cost, g and the upper triangle of H at the current values; false as
  // EvaluateCost, or when a Plus Jacobian fails or g is not finite.
  bool Assemble(double* cost);

  const Eigen::SparseMatrix<double>& hessian() const { return H_; }  // upper triangle
  const Eigen::VectorXd& gradient() const { return g_; }

 private:
  // Per-thread scratch reused across terms.
  struct Scratch {
    Eigen::VectorXd residual;
    std::vector<RowMajor> ambient_jac;
    std::vector<double*> jac_ptrs;
    std::vector<Eigen::MatrixXd> tangent_jac;
    Eigen::MatrixXd block;
  };

  void Layout();
  Eigen::VectorXi BlockOrdering(int num_candidates) const;
  // How many threads share the terms (1 when there are too few to pay for a thread).
  int Threads() const;
  // ½ Σ ρ of the terms [begin, end); false when one cannot be evaluated.
  bool CostOfTerms(size_t begin, size_t end, Eigen::VectorXd* residual, double* cost) const;
  // Adds the terms [begin, end) into `values` (H's value array) and `g`.
  bool AddTerms(size_t begin, size_t end, Scratch* s, double* values, Eigen::VectorXd* g,
                double* cost) const;
  // AddTerms for one term of NR residuals on two free, non-Euclidean blocks of
  // ambient size A and tangent size T (every relative-pose edge: SE(2) 3/3/3,
  // SE(3) 6/7/6) on the stack, the products unrolled: with the general
  // path's dynamic matrices the block products were most of a small graph's
  // iteration.
  template <int NR, int A, int T>
  bool AddPairTerm(size_t t, double* values, Eigen::VectorXd* g, double* cost) const;

  const std::vector<LsqBlock>& blocks_;
  const std::vector<LsqTerm>& terms_;

  std::vector<int> free_;        // free block indices, in column order
  std::vector<int> free_index_;  // block → free index or −1
  std::vector<int> col_;         // first column of each free block
  std::vector<int> tangent_;     // tangent size of each free block
  int n_ = 0;
  std::vector<std::vector<int>> term_free_;  // each term's free blocks, in argument order
  std::vector<std::vector<const double*>> params_;
  // For each term and each pair (a, b) of its free blocks with a ≤ b: the
  // offset of block row a within block column b's columns of H.
  std::vector<std::vector<int>> pair_pos_;
  // Each term's fixed-size path: 0 the general one, else kPair3 or kPair6.
  enum PairShape : unsigned char { kGeneral, kPair3, kPair6 };
  std::vector<PairShape> shape_;

  Eigen::SparseMatrix<double> H_;
  Eigen::VectorXd g_;
  std::vector<RowMajor> plus_jacobian_;

  int num_threads_;
  std::vector<Scratch> scratch_;                // one per thread
  std::vector<std::vector<double>> partial_h_;  // threads 1.. : their H values
  std::vector<Eigen::VectorXd> partial_g_;      // and g
  std::vector<Eigen::VectorXd> residuals_;      // cost-only evaluations, per thread
};

}  // namespace boxplus::internal
