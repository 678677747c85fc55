#include "boxplus/determinedness.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "boxplus/errors.h"
#include "solver/sparse_cholesky.h"

namespace boxplus {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Columns this small are analysed by a dense SVD of J D⁻¹.
constexpr int kDenseColumns = 64;
// The shift of the normal matrix, relative to its largest eigenvalue: large
// enough that the factorisation of a matrix with a big null space stays
// stable, small enough that the near-null eigenvalues it gathers into the
// block are few (the Ritz values on J separate them exactly).
constexpr double kNullSpaceShift = 1e-8;
// For covariances, where refinement removes the shift's bias.
constexpr double kCovarianceShift = 1e-12;
// Subspace iterations per block size: with the shift, the null components
// converge by λ/(λ + λ_k) ≤ 10⁻³ per step once the block reaches past the
// near-null eigenvalues (checked below), so four reach ~10⁻¹².
constexpr int kIterations = 4;

Eigen::MatrixXd Orthonormalise(const Eigen::MatrixXd& x) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(x);
  return qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), x.cols());
}

// Largest eigenvalue of the (positive semi-definite) H by power iteration;
// accurate to a few per cent, which is all a relative threshold needs.
double LargestEigenvalue(const Sparse& H) {
  Eigen::VectorXd x = Eigen::VectorXd::Ones(H.rows()) / std::sqrt(double(H.rows()));
  double lambda = 0.0;
  for (int it = 0; it < 50; ++it) {
    Eigen::VectorXd y = H.selfadjointView<Eigen::Upper>() * x;
    const double norm = y.norm();
    if (norm == 0.0) return 0.0;
    const double previous = lambda;
    lambda = x.dot(y);
    x = y / norm;
    if (it > 5 && std::abs(lambda - previous) <= 1e-3 * lambda) break;
  }
  return lambda;
}

// Null-space basis (orthonormal columns) of the equilibrated J (all columns
// touched), and its largest singular value.
Eigen::MatrixXd NullSpace(const Sparse& Js, double tolerance, double* s_max) {
  const int n = static_cast<int>(Js.cols());
  if (n <= kDenseColumns) {
    Eigen::BDCSVD<Eigen::MatrixXd> svd(Eigen::MatrixXd(Js), Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();  // descending, length min(m, n)
    *s_max = s.size() ? s(0) : 0.0;
    int rank = 0;
    while (rank < s.size() && s(rank) >= tolerance * *s_max && s(rank) > 0.0) ++rank;
    return svd.matrixV().rightCols(n - rank);
  }
  Sparse H = (Js.transpose() * Js).pruned().triangularView<Eigen::Upper>();
  const double lambda_max = LargestEigenvalue(H);
  *s_max = std::sqrt(lambda_max);
  internal::SparseCholesky cholesky;
  cholesky.Analyse(H);
  // One factorisation of the shifted matrix for every iteration and block
  // size (a larger shift only if it fails).
  double shift = kNullSpaceShift * lambda_max;
  bool factorised = false;
  for (int attempt = 0; attempt < 6 && !factorised; ++attempt, shift *= 100.0) {
    factorised = cholesky.FactoriseShifted(H, shift);
    if (factorised) break;
  }
  BOXPLUS_CHECK(factorised, "determinedness: the normal matrix does not factorise");
  std::mt19937 rng(12345);  // deterministic: the same answer on every run
  std::normal_distribution<double> normal;
  int k = std::min(n, 16);
  for (;;) {
    Eigen::MatrixXd x = Eigen::MatrixXd::NullaryExpr(n, k, [&] { return normal(rng); });
    x = Orthonormalise(x);
    for (int it = 0; it < kIterations && factorised; ++it) {
      Eigen::MatrixXd y;
      factorised = cholesky.SolveFactorised(x, &y);
      if (factorised) x = Orthonormalise(y);
    }
    BOXPLUS_CHECK(factorised, "determinedness: the normal matrix does not factorise");
    // Rayleigh–Ritz on J itself: singular values of J D⁻¹ X.
    const Eigen::MatrixXd jx = Js * x;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(jx, Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();  // descending
    const int kk = static_cast<int>(x.cols());
    Eigen::VectorXd sv = Eigen::VectorXd::Zero(kk);  // rows of J may be fewer than k
    sv.head(s.size()) = s;
    int nullity = 0;
    for (int i = 0; i < kk; ++i) nullity += sv(i) < tolerance * *s_max;
    // The block must reach past every eigenvalue near the shift, else a null
    // vector may still be outside it.
    const double reach = sv.size() ? sv(0) * sv(0) : 0.0;
    if ((nullity < kk && reach > 1e3 * shift) || k == n) {
      const Eigen::MatrixXd ritz = x * svd.matrixV();
      return ritz.rightCols(nullity);
    }
    k = std::min(n, 2 * k);
  }
}

// The same subspace with the coordinate axes it contains as its first basis
// vectors ("p.z" reads better than "0.6 p.z + 0.8 p.x" when both are free),
// then an orthonormal basis of the rest.
Eigen::MatrixXd AxesFirst(const Eigen::MatrixXd& u) {
  std::vector<int> axes;
  for (int i = 0; i < u.rows(); ++i) {
    if (u.row(i).squaredNorm() > 1.0 - 1e-8) axes.push_back(i);
  }
  if (axes.empty()) return u;
  const int a = static_cast<int>(axes.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(u.rows(), u.cols());
  for (int j = 0; j < a; ++j) out(axes[j], j) = 1.0;
  if (a < u.cols()) {
    Eigen::MatrixXd rest = u;
    for (int i : axes) rest.row(i).setZero();  // u minus its part along the axes
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(rest, Eigen::ComputeThinU);
    out.rightCols(u.cols() - a) = svd.matrixU().leftCols(u.cols() - a);
  }
  return out;
}

std::string Number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", x);
  return buf;
}

std::string DescribeDirection(const Eigen::VectorXd& u, const std::vector<std::string>& labels) {
  auto label = [&](int i) {
    return i < static_cast<int>(labels.size()) ? labels[i] : "d" + std::to_string(i);
  };
  std::vector<int> order(u.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return std::abs(u(a)) > std::abs(u(b)); });
  const double top = std::abs(u(order[0]));
  std::vector<int> parts;
  for (int i : order) {
    if (std::abs(u(i)) >= 0.05 * top) parts.push_back(i);
  }
  if (parts.size() == 1) return label(parts[0]);
  if (parts.size() > 3) {
    // Past three terms the numbers stop helping a reader: name what it mixes.
    std::string out = "a mix of " + label(parts[0]);
    for (size_t j = 1; j < parts.size(); ++j) out += ", " + label(parts[j]);
    return out;
  }
  // Sign so that the largest component is positive.
  const double sign = u(order[0]) < 0 ? -1.0 : 1.0;
  std::string out;
  for (size_t j = 0; j < parts.size(); ++j) {
    const double c = sign * u(parts[j]);
    if (j == 0) {
      out += Number(c) + " " + label(parts[j]);
    } else {
      out += (c < 0 ? " - " : " + ") + Number(std::abs(c)) + " " + label(parts[j]);
    }
  }
  return out;
}

}  // namespace

const UndeterminedVariable* Determinedness::Find(int id) const {
  for (const auto& u : undetermined) {
    if (u.variable == id) return &u;
  }
  return nullptr;
}

Determinedness AnalyseDeterminedness(const Sparse& jacobian, const std::vector<int>& variables,
                                     const std::vector<int>& column_offsets,
                                     const DeterminednessOptions& options) {
  BOXPLUS_CHECK(variables.size() == column_offsets.size(),
                "determinedness: one column offset per variable");
  BOXPLUS_CHECK(options.relative_tolerance > 0 && options.relative_tolerance < 1,
                "determinedness: relative_tolerance must be in (0, 1)");
  BOXPLUS_CHECK(options.support_tolerance > 0 && options.support_tolerance < 1,
                "determinedness: support_tolerance must be in (0, 1)");
  Determinedness out;
  const int n = static_cast<int>(jacobian.cols());
  out.num_columns = n;
  out.tolerance = options.relative_tolerance;
  out.variables = variables;
  out.column_offsets = column_offsets;
  out.column_norms = Eigen::VectorXd::Zero(n);
  for (int c = 0; c < n; ++c) out.column_norms(c) = jacobian.col(c).norm();

  // Touched columns, equilibrated; untouched ones are null directions outright.
  std::vector<int> touched, untouched;
  for (int c = 0; c < n; ++c) (out.column_norms(c) > 0 ? touched : untouched).push_back(c);
  Eigen::MatrixXd null_touched(touched.size(), 0);
  if (!touched.empty()) {
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(jacobian.nonZeros());
    for (size_t j = 0; j < touched.size(); ++j) {
      const int c = touched[j];
      for (Sparse::InnerIterator it(jacobian, c); it; ++it) {
        entries.emplace_back(static_cast<int>(it.row()), static_cast<int>(j),
                             it.value() / out.column_norms(c));
      }
    }
    Sparse Js(jacobian.rows(), static_cast<int>(touched.size()));
    Js.setFromTriplets(entries.begin(), entries.end());
    null_touched = NullSpace(Js, options.relative_tolerance, &out.largest_singular_value);
  }
  const int nullity = static_cast<int>(null_touched.cols() + untouched.size());
  out.rank = n - nullity;
  out.null_space = Eigen::MatrixXd::Zero(n, nullity);
  for (size_t j = 0; j < touched.size(); ++j) {
    out.null_space.row(touched[j]).head(null_touched.cols()) = null_touched.row(j);
  }
  for (size_t k = 0; k < untouched.size(); ++k) {
    out.null_space(untouched[k], null_touched.cols() + k) = 1.0;
  }
  if (nullity == 0) return out;

  // Per variable: the directions the null space reaches, and which null
  // vectors (hence which other variables) they share.
  const int nv = static_cast<int>(variables.size());
  std::vector<std::vector<int>> vectors_of(nv);  // null vectors moving each variable
  std::vector<Eigen::MatrixXd> blocks(nv);
  for (int k = 0; k < nv; ++k) {
    const int begin = column_offsets[k];
    const int end = k + 1 < nv ? column_offsets[k + 1] : n;
    blocks[k] = out.null_space.middleRows(begin, end - begin);
    for (int j = 0; j < nullity; ++j) {
      if (blocks[k].col(j).norm() > options.support_tolerance) vectors_of[k].push_back(j);
    }
  }
  for (int k = 0; k < nv; ++k) {
    if (vectors_of[k].empty()) continue;
    UndeterminedVariable u;
    u.variable = variables[k];
    // The block in tangent coordinates: a null vector x of J D⁻¹ is the
    // tangent direction D⁻¹ x.
    const int begin = column_offsets[k];
    Eigen::MatrixXd block = blocks[k];
    for (int r = 0; r < block.rows(); ++r) {
      const double d = out.column_norms(begin + r);
      if (d > 0) block.row(r) /= d;
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(block, Eigen::ComputeFullU);
    const Eigen::VectorXd& s = svd.singularValues();
    int r = 0;
    // Tangent directions within the reach of the null space; the scale is
    // the block's largest singular value (its units are the variable's).
    while (r < s.size() && s(r) > options.support_tolerance * std::max(s(0), 1e-300)) ++r;
    u.directions = AxesFirst(svd.matrixU().leftCols(r));
    for (int j = 0; j < nv; ++j) {
      if (j == k) continue;
      const bool shares = std::any_of(vectors_of[j].begin(), vectors_of[j].end(), [&](int v) {
        return std::find(vectors_of[k].begin(), vectors_of[k].end(), v) != vectors_of[k].end();
      });
      if (shares) u.moves_with.push_back(variables[j]);
    }
    out.undetermined.push_back(std::move(u));
  }
  return out;
}

Eigen::MatrixXd CovarianceOfDeterminedColumns(const Sparse& jacobian, const Determinedness& d,
                                              const std::vector<int>& columns) {
  const int n = static_cast<int>(jacobian.cols());
  BOXPLUS_CHECK(d.num_columns == n, "determinedness: analysed for another Jacobian");
  const Eigen::MatrixXd& N = d.null_space;
  for (int c : columns) {
    BOXPLUS_CHECK(c >= 0 && c < n, "covariance: column ", c, " out of range");
    BOXPLUS_CHECK(d.column_norms(c) > 0 && N.row(c).norm() <= 1e-6, "covariance: column ", c,
                  " is not determined");
  }
  const int k = static_cast<int>(columns.size());
  if (k == 0) return Eigen::MatrixXd(0, 0);
  // Equilibrated normal matrix over the touched columns; untouched ones get a
  // unit diagonal (their null vectors are projected out below).
  Eigen::VectorXd scale(n);
  for (int c = 0; c < n; ++c) scale(c) = d.column_norms(c) > 0 ? 1.0 / d.column_norms(c) : 0.0;
  const Sparse Js = jacobian * scale.asDiagonal();
  Sparse H = (Js.transpose() * Js).pruned();
  for (int c = 0; c < n; ++c) {
    if (d.column_norms(c) == 0) H.coeffRef(c, c) = 1.0;
  }
  H = H.triangularView<Eigen::Upper>();
  const double s_max = d.largest_singular_value > 0 ? d.largest_singular_value : 1.0;
  internal::SparseCholesky cholesky;
  cholesky.Analyse(H);
  auto project = [&](Eigen::MatrixXd& x) { x -= N * (N.transpose() * x); };
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, k);
  for (int j = 0; j < k; ++j) b(columns[j], j) = 1.0;
  project(b);
  double shift = kCovarianceShift * s_max * s_max;
  bool factorised = false;
  for (int attempt = 0; attempt < 6 && !factorised; ++attempt, shift *= 100.0) {
    factorised = cholesky.FactoriseShifted(H, shift);
    if (factorised) break;
  }
  Eigen::MatrixXd x;
  if (factorised && cholesky.SolveFactorised(b, &x)) {
    project(x);
    // Iterative refinement towards H⁺b on the range of H: the shift's error
    // shrinks by λ/(λ + λᵢ) per step.
    for (int it = 0; it < 2; ++it) {
      Eigen::MatrixXd r = b - H.selfadjointView<Eigen::Upper>() * x;
      project(r);
      Eigen::MatrixXd dx;
      if (!cholesky.SolveFactorised(r, &dx)) break;
      project(dx);
      x += dx;
    }
    Eigen::MatrixXd cov(k, k);
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) {
        cov(i, j) = x(columns[i], j) * scale(columns[i]) * scale(columns[j]);
      }
    }
    return 0.5 * (cov + cov.transpose());
  }
  throw Error("covariance: the normal matrix does not factorise");
}

std::string DescribeUndetermined(const Determinedness& d,
                                 const std::function<std::string(int)>& name,
                                 const std::function<std::vector<std::string>(int)>& labels) {
  // Past a few variables a list stops being read: the rest are counted.
  constexpr size_t kShown = 8;
  std::string out;
  // A gauge: every undetermined variable free in all its directions and tied to all
  // the others, i.e. the problem (or the part of it these variables form) can move
  // as a whole. Said by name, since its remedy differs from missing data's.
  bool gauge = d.undetermined.size() > 1;
  for (const auto& u : d.undetermined) {
    gauge = gauge && u.directions.cols() == u.directions.rows() &&
            u.moves_with.size() + 1 == d.undetermined.size();
  }
  if (gauge) {
    out =
        "the position of the whole (a gauge freedom: these variables move together "
        "without changing any residual; fix one or give one a prior): ";
  }
  const size_t prefix = out.size();
  size_t shown = 0;
  for (const auto& u : d.undetermined) {
    if (shown == kShown) {
      out += "; and " + std::to_string(d.undetermined.size() - kShown) + " more variables";
      break;
    }
    ++shown;
    if (out.size() > prefix) out += "; ";
    out += "'" + name(u.variable) + "': ";
    const std::vector<std::string> l = labels ? labels(u.variable) : std::vector<std::string>{};
    const int dim = static_cast<int>(u.directions.rows());
    if (u.directions.cols() == dim && dim > 1) {
      out += "all " + std::to_string(dim) + " directions";
    } else {
      for (int j = 0; j < u.directions.cols(); ++j) {
        if (j) out += ", ";
        out += DescribeDirection(u.directions.col(j), l);
      }
    }
    if (!u.moves_with.empty()) {
      out += " (tied to ";
      const size_t shown = std::min<size_t>(u.moves_with.size(), 3);
      for (size_t j = 0; j < shown; ++j) {
        out += (j ? ", '" : "'") + name(u.moves_with[j]) + "'";
      }
      if (u.moves_with.size() > shown) {
        out += " and " + std::to_string(u.moves_with.size() - shown) + " more";
      }
      out += ")";
    }
  }
  return out;
}

}  // namespace boxplus
