// Which directions of a solution the measurements do not determine.
//
// At a solution X̂ the covariance of the ⊞-estimate is (JᵀJ)⁻¹ for the whitened
// Jacobian J of every residual with respect to the tangent coordinates of the
// free variables (Hertzberg et al. 2013, §4.3, eq. 40). It exists only when J
// has full column rank. A direction δ with J δ = 0 changes no residual to first
// order: the data say nothing about it, and any σ reported along it (or along
// a direction mixed with it) is an artefact of the factorisation, not of the
// data. Ceres' own covariance detects a rank deficiency only when J has at
// least as many rows as columns, so boxplus decides itself.
//
// The test. Columns are equilibrated first (J D⁻¹, D = diag of the column
// norms) so that units do not decide: a translation in millimetres and a
// rotation in radians weigh alike. A direction is undetermined when its
// singular value of J D⁻¹ is below `relative_tolerance` (10⁻⁹) times the
// largest one; a column that no residual touches is undetermined outright.
// The null space is found by subspace iteration with one sparse Cholesky
// factorisation of the shifted DᵀJᵀJD⁻¹ + λI (λ = 10⁻¹² of its largest
// eigenvalue), and the decision is taken on ‖J D⁻¹ x‖ of the Ritz vectors x,
// computed from J itself, so the squaring of the condition number in JᵀJ does
// not blur the threshold. Small problems (≤ 64 columns) use a dense SVD of
// J D⁻¹. The cost is one factorisation of the size of a Gauss–Newton step.
//
// A variable is undetermined when the null space has weight on one of its
// columns (above `support_tolerance`, in the orthonormal null basis); its
// free directions are the column space of the null basis restricted to it,
// reported in its own tangent coordinates. A null vector spread over several
// variables is a freedom they share (e.g. a gauge: every pose may move
// together); the determined variables keep their covariance, the block of the
// pseudo-inverse (JᵀJ)⁺, which no choice of gauge changes.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace boxplus {

struct DeterminednessOptions {
  // Singular values of the equilibrated Jacobian below this fraction of the
  // largest count as zero.
  double relative_tolerance = 1e-9;
  // A column whose row of the orthonormal null basis has a norm above this
  // is moved by the null space.
  double support_tolerance = 1e-6;
};

// The tangent directions of one variable that the data leave free.
struct UndeterminedVariable {
  int variable = -1;
  // Orthonormal columns in the variable's tangent coordinates (its ⊞ order),
  // the subspace of its tangent space the null space reaches.
  Eigen::MatrixXd directions;
  // The other variables these directions are tied to (share a null vector
  // with); empty when the variable is free on its own.
  std::vector<int> moves_with;
};

struct Determinedness {
  int num_columns = 0;                  // tangent coordinates of the free variables
  int rank = 0;                         // num_columns minus the dimension of the null space
  double largest_singular_value = 0.0;  // of the equilibrated Jacobian
  double tolerance = 0.0;               // relative, as in the options
  std::vector<int> variables;           // free variables, in id order
  std::vector<int> column_offsets;      // their first column
  // Orthonormal basis of the null space of J D⁻¹ (num_columns × nullity),
  // in equilibrated coordinates.
  Eigen::MatrixXd null_space;
  // Column scales D (the norms of J's columns; 0 for untouched columns).
  Eigen::VectorXd column_norms;
  std::vector<UndeterminedVariable> undetermined;

  bool determined() const { return rank == num_columns; }
  int nullity() const { return num_columns - rank; }
  // The entry of `undetermined` for variable `id`, or null.
  const UndeterminedVariable* Find(int id) const;
};

// The analysis of a whitened Jacobian J (rows: residuals, columns: the
// tangent coordinates of `variables`, variable k owning the columns from
// column_offsets[k] up to the next offset or J.cols()).
Determinedness AnalyseDeterminedness(const Eigen::SparseMatrix<double>& jacobian,
                                     const std::vector<int>& variables,
                                     const std::vector<int>& column_offsets,
                                     const DeterminednessOptions& options = {});

// The joint covariance (JᵀJ)⁺ of the listed columns (each a tangent
// coordinate of a determined variable) when J is rank-deficient elsewhere:
// the pseudo-inverse block, which no gauge choice changes. Computed with one
// factorisation of the shifted normal matrix and two steps of iterative
// refinement on the range of JᵀJ.
Eigen::MatrixXd CovarianceOfDeterminedColumns(const Eigen::SparseMatrix<double>& jacobian,
                                              const Determinedness& determinedness,
                                              const std::vector<int>& columns);

// The undetermined variables and their free directions, for messages:
// "'b': x, y (tied to 'a'); 'a': x, y (tied to 'b')". `name` gives a
// variable's name; `labels` (optional) the names of its tangent directions
// (e.g. "rotation about z"), else they are "d0", "d1", ...; a direction that
// mixes several is written as their combination, "0.71 x + 0.71 y". Eight
// variables at most are named; the rest are counted ("and 22 more variables").
// When every undetermined variable is free in all its directions and tied to all
// the others (the problem can move as a whole) the text starts "the position of the
// whole (a gauge freedom: ...)".
std::string DescribeUndetermined(
    const Determinedness& determinedness, const std::function<std::string(int)>& name,
    const std::function<std::vector<std::string>(int)>& labels = nullptr);

}  // namespace boxplus
