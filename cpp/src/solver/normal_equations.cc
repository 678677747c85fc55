#include "normal_equations.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/OrderingMethods>

#include "boxplus/errors.h"

namespace boxplus::internal {
namespace {

// ρ(s)/2 and the weight ρ'(s) of a term with squared residual norm s.
double HalfRho(const LsqTerm& term, double s, double* weight) {
  if (!term.loss) {
    if (weight) *weight = 1.0;
    return 0.5 * s;
  }
  double rho[3];
  term.loss->Evaluate(s, rho);
  if (weight) *weight = rho[1];
  return 0.5 * rho[0];
}

}  // namespace

NormalEquations::NormalEquations(const std::vector<LsqBlock>& blocks,
                                 const std::vector<LsqTerm>& terms)
    : blocks_(blocks), terms_(terms) {
  Layout();
}

void NormalEquations::Layout() {
  const int nb = static_cast<int>(blocks_.size());
  // Blocks no term depends on stay out of the system (as in Ceres).
  std::vector<bool> used(nb, false);
  for (const LsqTerm& term : terms_) {
    for (int b : term.blocks) used[b] = true;
  }
  std::vector<int> candidates;
  for (int b = 0; b < nb; ++b) {
    if (used[b] && !blocks_[b].fixed && blocks_[b].manifold->TangentSize() > 0) {
      candidates.push_back(b);
    }
  }
  free_index_.assign(nb, -1);
  for (size_t k = 0; k < candidates.size(); ++k) free_index_[candidates[k]] = static_cast<int>(k);
  const Eigen::VectorXi order = BlockOrdering(static_cast<int>(candidates.size()));
  for (Eigen::Index k = 0; k < order.size(); ++k) {
    const int b = candidates[order[k]];
    free_index_[b] = static_cast<int>(k);
    free_.push_back(b);
    col_.push_back(n_);
    n_ += blocks_[b].manifold->TangentSize();
  }
  const int nf = static_cast<int>(free_.size());
  tangent_.resize(nf);
  for (int f = 0; f < nf; ++f) tangent_[f] = blocks_[free_[f]].manifold->TangentSize();

  std::vector<std::vector<int>> rows_of(nf);  // block rows i ≤ j of block column j
  term_free_.resize(terms_.size());
  params_.resize(terms_.size());
  for (size_t t = 0; t < terms_.size(); ++t) {
    std::vector<int>& fs = term_free_[t];
    for (int b : terms_[t].blocks) {
      params_[t].push_back(blocks_[b].x);
      if (free_index_[b] >= 0) fs.push_back(free_index_[b]);
    }
    std::vector<int> sorted = fs;
    std::sort(sorted.begin(), sorted.end());
    for (size_t a = 0; a < sorted.size(); ++a) {
      for (size_t c = a; c < sorted.size(); ++c) rows_of[sorted[c]].push_back(sorted[a]);
    }
  }
  for (int f = 0; f < nf; ++f) {
    std::vector<int>& v = rows_of[f];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  // Offset of block row i within the columns of block column j.
  std::vector<std::vector<int>> pos_in_col(nf);
  std::vector<int> column_height(nf, 0);
  long long nnz = 0;
  for (int f = 0; f < nf; ++f) {
    for (int i : rows_of[f]) {
      pos_in_col[f].push_back(column_height[f]);
      column_height[f] += tangent_[i];
    }
    nnz += static_cast<long long>(column_height[f]) * tangent_[f];
  }
  // Eigen's sparse matrix indexes its entries with int.
  BOXPLUS_CHECK(nnz <= std::numeric_limits<int>::max(), "the normal equations have ", nnz,
                " non-zeros, more than a sparse matrix with int indices holds");
  H_.resize(n_, n_);
  H_.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = H_.outerIndexPtr();
  int* inner = H_.innerIndexPtr();
  int k = 0;
  for (int f = 0; f < nf; ++f) {
    for (int c = 0; c < tangent_[f]; ++c) {
      outer[col_[f] + c] = k;
      for (int i : rows_of[f]) {
        for (int r = 0; r < tangent_[i]; ++r) inner[k++] = col_[i] + r;
      }
    }
  }
  outer[n_] = k;
  pair_pos_.resize(terms_.size());
  for (size_t t = 0; t < terms_.size(); ++t) {
    const std::vector<int>& fs = term_free_[t];
    for (size_t a = 0; a < fs.size(); ++a) {
      for (size_t b = 0; b < fs.size(); ++b) {
        if (fs[a] > fs[b]) continue;
        const std::vector<int>& rows = rows_of[fs[b]];
        const auto it = std::lower_bound(rows.begin(), rows.end(), fs[a]);
        pair_pos_[t].push_back(pos_in_col[fs[b]][it - rows.begin()]);
      }
    }
  }
  g_.setZero(n_);
  plus_jacobian_.resize(nf);
}

// AMD order of the candidate blocks (free_index_ holding their provisional
// numbers): order[k] is the provisional number of the k-th block.
Eigen::VectorXi NormalEquations::BlockOrdering(int num_candidates) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (int f = 0; f < num_candidates; ++f) entries.emplace_back(f, f, 1.0);
  std::vector<int> fs;
  for (const LsqTerm& term : terms_) {
    fs.clear();
    for (int b : term.blocks) {
      if (free_index_[b] >= 0) fs.push_back(free_index_[b]);
    }
    for (int a : fs) {
      for (int c : fs) entries.emplace_back(a, c, 1.0);
    }
  }
  Eigen::SparseMatrix<double> pattern(num_candidates, num_candidates);
  pattern.setFromTriplets(entries.begin(), entries.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  Eigen::AMDOrdering<int>()(pattern, perm);
  return perm.indices();
}

bool NormalEquations::EvaluateCost(double* cost) {
  double total = 0.0;
  for (size_t t = 0; t < terms_.size(); ++t) {
    const LsqTerm& term = terms_[t];
    residual_.resize(term.cost->num_residuals());
    if (!term.cost->Evaluate(params_[t].data(), residual_.data(), nullptr)) return false;
    total += HalfRho(term, residual_.squaredNorm(), nullptr);
  }
  *cost = total;
  return std::isfinite(total);
}

bool NormalEquations::Assemble(double* cost) {
  for (size_t f = 0; f < free_.size(); ++f) {
    const LsqBlock& blk = blocks_[free_[f]];
    if (blk.euclidean) continue;
    plus_jacobian_[f].resize(blk.manifold->AmbientSize(), blk.manifold->TangentSize());
    if (!blk.manifold->PlusJacobian(blk.x, plus_jacobian_[f].data())) return false;
  }
  std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
  g_.setZero();
  const int* outer = H_.outerIndexPtr();
  double* values = H_.valuePtr();
  double total = 0.0;
  for (size_t t = 0; t < terms_.size(); ++t) {
    const LsqTerm& term = terms_[t];
    const int nr = term.cost->num_residuals();
    const auto& sizes = term.cost->parameter_block_sizes();
    const size_t np = term.blocks.size();
    residual_.resize(nr);
    ambient_jac_.resize(np);
    jac_ptrs_.assign(np, nullptr);
    for (size_t k = 0; k < np; ++k) {
      if (free_index_[term.blocks[k]] < 0) continue;
      ambient_jac_[k].resize(nr, sizes[k]);
      jac_ptrs_[k] = ambient_jac_[k].data();
    }
    if (!term.cost->Evaluate(params_[t].data(), residual_.data(), jac_ptrs_.data())) {
      return false;
    }
    double w = 1.0;
    total += HalfRho(term, residual_.squaredNorm(), &w);
    // Tangent Jacobians of the free blocks, in the order of term_free_.
    tangent_jac_.resize(term_free_[t].size());
    for (size_t k = 0, j = 0; k < np; ++k) {
      const int f = free_index_[term.blocks[k]];
      if (f < 0) continue;
      if (blocks_[term.blocks[k]].euclidean) {
        tangent_jac_[j++] = ambient_jac_[k];
      } else {
        tangent_jac_[j++].noalias() = ambient_jac_[k] * plus_jacobian_[f];
      }
    }
    const std::vector<int>& fs = term_free_[t];
    for (size_t a = 0; a < fs.size(); ++a) {
      g_.segment(col_[fs[a]], tangent_[fs[a]]).noalias() +=
          w * tangent_jac_[a].transpose() * residual_;
    }
    size_t p = 0;
    for (size_t a = 0; a < fs.size(); ++a) {
      for (size_t b = 0; b < fs.size(); ++b) {
        if (fs[a] > fs[b]) continue;
        block_.noalias() = w * tangent_jac_[a].transpose() * tangent_jac_[b];
        const int pos = pair_pos_[t][p++];
        for (int c = 0; c < tangent_[fs[b]]; ++c) {
          double* col = values + outer[col_[fs[b]] + c] + pos;
          for (int r = 0; r < tangent_[fs[a]]; ++r) col[r] += block_(r, c);
        }
      }
    }
  }
  *cost = total;
  return std::isfinite(total) && g_.allFinite();
}

}  // namespace boxplus::internal
