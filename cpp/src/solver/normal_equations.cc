#include "normal_equations.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <thread>

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
                                 const std::vector<LsqTerm>& terms, int num_threads)
    : blocks_(blocks), terms_(terms), num_threads_(std::max(1, num_threads)) {
  Layout();
  const int t = Threads();
  scratch_.resize(t);
  residuals_.resize(t);
  partial_h_.resize(t - 1);
  partial_g_.resize(t - 1);
}

int NormalEquations::Threads() const {
  // Below this many terms per thread, starting the threads costs more than
  // they save (a thread's start and join is tens of microseconds; the
  // cheapest terms, analytic 2D pose edges, take about 0.1 µs each).
  constexpr size_t kMinTermsPerThread = 512;
  const size_t useful = terms_.size() / kMinTermsPerThread;
  return static_cast<int>(std::max<size_t>(1, std::min<size_t>(num_threads_, useful)));
}

namespace {

// Runs body(thread, begin, end) over `threads` contiguous ranges of [0, n),
// the first on the calling thread; an exception of any range is rethrown here.
template <class Body>
bool ForRanges(int threads, size_t n, const Body& body) {
  if (threads <= 1) return body(0, size_t{0}, n);
  std::vector<char> ok(threads, 0);
  std::vector<std::exception_ptr> error(threads);
  auto run = [&](int k) {
    try {
      ok[k] = body(k, n * k / threads, n * (k + 1) / threads);
    } catch (...) {
      error[k] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int k = 1; k < threads; ++k) pool.emplace_back(run, k);
  run(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : error) {
    if (e) std::rethrow_exception(e);
  }
  return std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; });
}

}  // namespace

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
  shape_.assign(terms_.size(), kGeneral);
  for (size_t t = 0; t < terms_.size(); ++t) {
    const LsqTerm& term = terms_[t];
    const std::vector<int>& fs = term_free_[t];
    if (term.blocks.size() != 2 || fs.size() != 2) continue;
    if (blocks_[term.blocks[0]].euclidean || blocks_[term.blocks[1]].euclidean) continue;
    const int nr = term.cost->num_residuals();
    const auto& sizes = term.cost->parameter_block_sizes();
    const auto is = [&](int r, int a, int tan) {
      return nr == r && sizes[0] == a && sizes[1] == a && tangent_[fs[0]] == tan &&
             tangent_[fs[1]] == tan;
    };
    if (is(3, 3, 3)) shape_[t] = kPair3;
    if (is(6, 7, 6)) shape_[t] = kPair6;
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

bool NormalEquations::CostOfTerms(size_t begin, size_t end, Eigen::VectorXd* residual,
                                  double* cost) const {
  double total = 0.0;
  for (size_t t = begin; t < end; ++t) {
    const LsqTerm& term = terms_[t];
    residual->resize(term.cost->num_residuals());
    if (!term.cost->Evaluate(params_[t].data(), residual->data(), nullptr)) return false;
    total += HalfRho(term, residual->squaredNorm(), nullptr);
  }
  *cost = total;
  return true;
}

bool NormalEquations::EvaluateCost(double* cost) {
  const int threads = Threads();
  std::vector<double> part(threads, 0.0);
  const bool ok = ForRanges(threads, terms_.size(), [&](int k, size_t begin, size_t end) {
    return CostOfTerms(begin, end, &residuals_[k], &part[k]);
  });
  if (!ok) return false;
  double total = 0.0;
  for (double c : part) total += c;
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
  const int threads = Threads();
  const Eigen::Index nnz = H_.nonZeros();
  std::vector<double> part(threads, 0.0);
  const bool ok = ForRanges(threads, terms_.size(), [&](int k, size_t begin, size_t end) {
    double* values = H_.valuePtr();
    Eigen::VectorXd* g = &g_;
    if (k > 0) {  // the first thread adds into H itself, the others into copies
      partial_h_[k - 1].assign(nnz, 0.0);
      partial_g_[k - 1].setZero(n_);
      values = partial_h_[k - 1].data();
      g = &partial_g_[k - 1];
    } else {
      std::fill(values, values + nnz, 0.0);
      g_.setZero();
    }
    return AddTerms(begin, end, &scratch_[k], values, g, &part[k]);
  });
  if (!ok) return false;
  double total = part[0];
  for (int k = 1; k < threads; ++k) {
    Eigen::Map<Eigen::VectorXd>(H_.valuePtr(), nnz) +=
        Eigen::Map<const Eigen::VectorXd>(partial_h_[k - 1].data(), nnz);
    g_ += partial_g_[k - 1];
    total += part[k];
  }
  *cost = total;
  return std::isfinite(total) && g_.allFinite();
}

bool NormalEquations::AddTerms(size_t begin, size_t end, Scratch* s, double* values,
                               Eigen::VectorXd* g, double* cost) const {
  const int* outer = H_.outerIndexPtr();
  double total = 0.0;
  for (size_t t = begin; t < end; ++t) {
    if (shape_[t] == kPair6) {
      if (!AddPairTerm<6, 7, 6>(t, values, g, &total)) return false;
      continue;
    }
    if (shape_[t] == kPair3) {
      if (!AddPairTerm<3, 3, 3>(t, values, g, &total)) return false;
      continue;
    }
    const LsqTerm& term = terms_[t];
    const int nr = term.cost->num_residuals();
    const auto& sizes = term.cost->parameter_block_sizes();
    const size_t np = term.blocks.size();
    s->residual.resize(nr);
    s->ambient_jac.resize(np);
    s->jac_ptrs.assign(np, nullptr);
    for (size_t k = 0; k < np; ++k) {
      if (free_index_[term.blocks[k]] < 0) continue;
      s->ambient_jac[k].resize(nr, sizes[k]);
      s->jac_ptrs[k] = s->ambient_jac[k].data();
    }
    if (!term.cost->Evaluate(params_[t].data(), s->residual.data(), s->jac_ptrs.data())) {
      return false;
    }
    double w = 1.0;
    total += HalfRho(term, s->residual.squaredNorm(), &w);
    // Tangent Jacobians of the free blocks, in the order of term_free_.
    s->tangent_jac.resize(term_free_[t].size());
    for (size_t k = 0, j = 0; k < np; ++k) {
      const int f = free_index_[term.blocks[k]];
      if (f < 0) continue;
      if (blocks_[term.blocks[k]].euclidean) {
        s->tangent_jac[j++] = s->ambient_jac[k];
      } else {
        s->tangent_jac[j++].noalias() = s->ambient_jac[k] * plus_jacobian_[f];
      }
    }
    const std::vector<int>& fs = term_free_[t];
    for (size_t a = 0; a < fs.size(); ++a) {
      g->segment(col_[fs[a]], tangent_[fs[a]]).noalias() +=
          w * s->tangent_jac[a].transpose() * s->residual;
    }
    size_t p = 0;
    for (size_t a = 0; a < fs.size(); ++a) {
      for (size_t b = 0; b < fs.size(); ++b) {
        if (fs[a] > fs[b]) continue;
        s->block.noalias() = w * s->tangent_jac[a].transpose() * s->tangent_jac[b];
        const int pos = pair_pos_[t][p++];
        for (int c = 0; c < tangent_[fs[b]]; ++c) {
          double* col = values + outer[col_[fs[b]] + c] + pos;
          for (int r = 0; r < tangent_[fs[a]]; ++r) col[r] += s->block(r, c);
        }
      }
    }
  }
  *cost = total;
  return true;
}

template <int NR, int A, int T>
bool NormalEquations::AddPairTerm(size_t t, double* values, Eigen::VectorXd* g,
                                  double* cost) const {
  // Ceres' Jacobians are row-major, one row per residual.
  using AmbientJacobian = Eigen::Matrix<double, NR, A, Eigen::RowMajor>;
  using PlusJacobian = Eigen::Matrix<double, A, T, Eigen::RowMajor>;
  const LsqTerm& term = terms_[t];
  Eigen::Matrix<double, NR, 1> r;
  AmbientJacobian ambient[2];
  double* jac_ptrs[2] = {ambient[0].data(), ambient[1].data()};
  if (!term.cost->Evaluate(params_[t].data(), r.data(), jac_ptrs)) return false;
  double w = 1.0;
  *cost += HalfRho(term, r.squaredNorm(), &w);
  const std::vector<int>& fs = term_free_[t];
  Eigen::Matrix<double, NR, T> J[2];
  for (int k = 0; k < 2; ++k) {
    J[k].noalias() = ambient[k] * Eigen::Map<const PlusJacobian>(plus_jacobian_[fs[k]].data());
    g->template segment<T>(col_[fs[k]]).noalias() += w * J[k].transpose() * r;
  }
  // The pairs in the order of pair_pos_ (Layout): (a, b) with fs[a] ≤ fs[b].
  const int* outer = H_.outerIndexPtr();
  int p = 0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      if (fs[a] > fs[b]) continue;
      const Eigen::Matrix<double, T, T> block = w * J[a].transpose() * J[b];
      const int pos = pair_pos_[t][p++];
      for (int c = 0; c < T; ++c) {
        double* col = values + outer[col_[fs[b]] + c] + pos;
        for (int i = 0; i < T; ++i) col[i] += block(i, c);
      }
    }
  }
  return true;
}

}  // namespace boxplus::internal
