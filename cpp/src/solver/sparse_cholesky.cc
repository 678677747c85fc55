#include "sparse_cholesky.h"

#include <algorithm>
#include <mutex>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

namespace boxplus::internal {

struct SparseCholesky::Factors {
  Eigen::SimplicialLDLT<Matrix, Eigen::Upper, Eigen::NaturalOrdering<int>> simplicial;
  Eigen::CholmodSupernodalLLT<Matrix, Eigen::Upper> cholmod;
};

SparseCholesky::SparseCholesky(Orderings orderings)
    : factors_(std::make_unique<Factors>()), orderings_(orderings) {}
SparseCholesky::~SparseCholesky() = default;

std::vector<int> CholeskyColumnCounts(const Eigen::SparseMatrix<double>& upper) {
  const int n = static_cast<int>(upper.cols());
  std::vector<int> parent(n, -1), mark(n, -1), counts(n, 0);
  for (int k = 0; k < n; ++k) {
    // Row k of L is the union of the paths in the elimination tree from each
    // i < k with Hᵢₖ ≠ 0 up to k; k becomes the parent of the paths' roots.
    mark[k] = k;
    for (Eigen::SparseMatrix<double>::InnerIterator it(upper, k); it; ++it) {
      int i = static_cast<int>(it.index());
      if (i >= k) continue;
      for (; mark[i] != k; i = parent[i]) {
        if (parent[i] == -1) parent[i] = k;
        ++counts[i];
        mark[i] = k;
      }
    }
  }
  return counts;
}

double FillMeasure(const std::vector<int>& column_counts) {
  double squares = 0.0, total = 0.0;
  for (int c : column_counts) {
    squares += static_cast<double>(c) * c;
    total += c;
  }
  return total > 0 ? squares / total : 0.0;
}

void SparseCholesky::Analyse(const Matrix& H) {
  supernodal_ = FillMeasure(CholeskyColumnCounts(H)) > kSupernodalSwitch;
  if (supernodal_) {
    // The orderings CHOLMOD tries, keeping the one of least fill (nnz(L)).
    cholmod_common& c = factors_->cholmod.cholmod();
    c.nmethods = orderings_ == Orderings::kLeastFill ? 3 : 1;
    c.method[0].ordering = CHOLMOD_NATURAL;  // the block AMD order H arrives in
    c.method[1].ordering = CHOLMOD_AMD;
    c.method[2].ordering = CHOLMOD_METIS;
    c.postorder = 1;
    // METIS keeps its random generator in global state (GKlib's), so two analyses
    // at once draw from one sequence and may order differently than each alone:
    // two graphs solved on two threads differed from the serial solves in the last
    // bits. The analyses are serialised (one per solve; the factorisations are not).
    static std::mutex metis_mutex;
    std::lock_guard<std::mutex> lock(metis_mutex);
    factors_->cholmod.analyzePattern(H);
  } else {
    factors_->simplicial.analyzePattern(H);
  }
}

std::string SparseCholesky::name() const {
  if (!supernodal_) return "Eigen simplicial LDLT";
  // The ordering CHOLMOD kept, read back from its common block.
  const cholmod_common& c = factors_->cholmod.cholmod();
  const bool chosen = c.selected >= 0 && c.selected < c.nmethods;
  const int ordering = chosen ? c.method[c.selected].ordering : CHOLMOD_NATURAL;
  const char* order = ordering == CHOLMOD_METIS ? "METIS"
                      : ordering == CHOLMOD_AMD ? "AMD"
                                                : "block AMD";
  return std::string("CHOLMOD supernodal LLT, ") + order + " order";
}

bool SparseCholesky::Factorise(const Matrix& H, double shift) {
  if (supernodal_) {
    factors_->cholmod.setShift(shift);
    factors_->cholmod.factorize(H);
    return factors_->cholmod.info() == Eigen::Success;
  }
  factors_->simplicial.setShift(shift);
  factors_->simplicial.factorize(H);
  return factors_->simplicial.info() == Eigen::Success;
}

bool SparseCholesky::Solve(const Matrix& H, const Eigen::VectorXd& b, Eigen::VectorXd* x) {
  return SolveDense(H, b, x, 8);
}

bool SparseCholesky::SolveUnshifted(const Matrix& H, const Eigen::MatrixXd& B, Eigen::MatrixXd* X) {
  return SolveDense(H, B, X, 1);
}

bool SparseCholesky::SolveFactorised(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) {
  if (supernodal_) {
    *X = factors_->cholmod.solve(B);
  } else {
    *X = factors_->simplicial.solve(B);
  }
  return X->allFinite();
}

template <class Dense>
bool SparseCholesky::SolveDense(const Matrix& H, const Dense& b, Dense* x, int attempts) {
  double shift = 0.0;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    if (Factorise(H, shift)) {
      if (supernodal_) {
        *x = factors_->cholmod.solve(b);
      } else {
        *x = factors_->simplicial.solve(b);
      }
      if (x->allFinite()) return true;
    }
    // Only a failed factorisation pays for the scan of the diagonal.
    shift =
        shift == 0.0 ? 1e-12 * std::max(1.0, H.diagonal().cwiseAbs().maxCoeff()) : shift * 100.0;
  }
  return false;
}

}  // namespace boxplus::internal
