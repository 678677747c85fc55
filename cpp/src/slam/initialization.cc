#include "boxplus/slam/initialization.h"

#include <cmath>
#include <complex>
#include <queue>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/OrderingMethods>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "../solver/sparse_cholesky.h"
#include "boxplus/errors.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/manifolds/se2.h"
#include "boxplus/manifolds/se3.h"
#include "boxplus/named_enum.h"
#include "nearest_rotation.h"

namespace boxplus::slam {
namespace {

using io::EdgeKind;
using io::Graph;
using io::VertexKind;

bool IsPose(VertexKind k) { return k == VertexKind::kSE2 || k == VertexKind::kSE3; }
bool IsPosePose(EdgeKind k) { return k == EdgeKind::kSE2 || k == EdgeKind::kSE3; }

// The file the graph came from, as a prefix of messages ("" if none).
std::string Where(const Graph& g) { return g.name.empty() ? "" : io::Escaped(g.name) + ": "; }
// "file:line: " of a record read from the file.
std::string Where(const Graph& g, int line) {
  if (g.name.empty() || line <= 0) return Where(g);
  return io::Escaped(g.name) + ":" + std::to_string(line) + ": ";
}

// Why a chordal system did not factorise: the graph is connected (checked
// first), so its matrix is positive definite in exact arithmetic, and only
// weights (κ or τ per edge, from the information matrices) that underflow,
// overflow or span more than a double resolves make it singular. Names the
// lightest and the heaviest pose-pose edge by line.
std::string SingularSystem(const Graph& g, const char* system, const std::vector<double>& w) {
  int lo = -1, hi = -1;
  for (size_t k = 0; k < g.edges.size(); ++k) {
    if (!IsPosePose(g.edges[k].kind)) continue;
    if (lo < 0 || w[k] < w[lo]) lo = static_cast<int>(k);
    if (hi < 0 || w[k] > w[hi]) hi = static_cast<int>(k);
  }
  std::ostringstream msg;
  msg << Where(g) << "chordal initialisation: singular " << system << " system";
  if (lo < 0) return msg.str();
  auto edge = [&](int k) {
    const io::Edge& e = g.edges[k];
    std::ostringstream s;
    s << w[k] << " (edge " << e.from << " -> " << e.to;
    if (e.line > 0) s << ", line " << e.line;
    s << ")";
    return s.str();
  };
  msg << ": the edges' weights from their information matrices range from " << edge(lo) << " to "
      << edge(hi)
      << ", beyond what a double factorisation resolves; repair those information matrices, or "
         "initialise with the spanning tree";
  return msg.str();
}

// The root (gauge) pose: root_id, else the first FIX id that is a pose (a FIX
// may name a landmark, which cannot root a tree of poses), else the first
// pose of the file.
int RootIndex(const Graph& g, int root_id) {
  if (root_id >= 0) {
    const int r = g.VertexIndex(root_id);
    BOXPLUS_CHECK(IsPose(g.vertices[r].kind), Where(g), "initialisation: root vertex ", root_id,
                  " is not a pose");
    return r;
  }
  for (int id : g.FixedIds()) {
    const int r = g.VertexIndex(id);
    if (IsPose(g.vertices[r].kind)) return r;
  }
  for (const auto& rec : g.order) {
    if (rec.type == Graph::RecordType::kVertex && IsPose(g.vertices[rec.index].kind)) {
      return rec.index;
    }
  }
  throw Error(Where(g) + "the graph has no pose vertex");
}

// Rigid transform of an ambient pose vector, homogeneous; 2D poses use the
// [x, y] rows and columns of the 4×4 matrix (as SE2::transform's 3×3).
Eigen::Matrix4d ToMatrix(VertexKind kind, const Eigen::VectorXd& x) {
  if (kind == VertexKind::kSE3) return SE3::FromAmbient(x.data()).transform();
  const Eigen::Matrix3d M = SE2::FromAmbient(x.data()).transform();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<2, 2>() = M.topLeftCorner<2, 2>();
  T.topRightCorner<2, 1>() = M.topRightCorner<2, 1>();
  return T;
}

Eigen::VectorXd FromMatrix(VertexKind kind, const Eigen::Matrix4d& T) {
  if (kind == VertexKind::kSE3) return SE3::FromMatrix(T).ambient();
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  M.topLeftCorner<2, 2>() = T.topLeftCorner<2, 2>();
  M.topRightCorner<2, 1>() = T.topRightCorner<2, 1>();
  return SE2::FromMatrix(M).ambient();
}

Eigen::Matrix4d EdgeMatrix(const io::Edge& e) {
  return ToMatrix(e.kind == EdgeKind::kSE2 ? VertexKind::kSE2 : VertexKind::kSE3, e.measurement);
}

// Places landmarks (vertices that are not poses) from their first observation.
void PlaceLandmarks(Graph* g, const std::vector<char>& pose_done) {
  std::vector<char> done(g->vertices.size(), 0);
  for (const io::Edge& e : g->edges) {
    // The observations a landmark can be placed from without a sensor offset;
    // landmarks seen only through other edges keep the file's estimate.
    if (e.kind != EdgeKind::kSE2Point2 && e.kind != EdgeKind::kSE3Point3 &&
        e.kind != EdgeKind::kSE2BearingRange) {
      continue;
    }
    const int a = g->EndIndex(e, 0), b = g->EndIndex(e, 1);
    if (done[b] || !pose_done[a]) continue;
    const Eigen::Matrix4d T = ToMatrix(g->vertices[a].kind, g->vertices[a].estimate);
    Eigen::Vector4d local(0, 0, 0, 1);
    if (e.kind == EdgeKind::kSE2BearingRange) {
      local.head<2>() << e.measurement[1] * std::cos(e.measurement[0]),
          e.measurement[1] * std::sin(e.measurement[0]);
    } else {
      local.head(e.measurement.size()) = e.measurement;
    }
    const Eigen::Vector4d world = T * local;
    g->vertices[b].estimate = world.head(g->vertices[b].estimate.size());
    g->vertices[b].has_estimate = true;
    done[b] = 1;
  }
}

// Adjacency over pose–pose edges: for each vertex index, (edge index, other).
std::vector<std::vector<std::pair<int, int>>> Adjacency(const Graph& g) {
  std::vector<std::vector<std::pair<int, int>>> adj(g.vertices.size());
  for (size_t k = 0; k < g.edges.size(); ++k) {
    const io::Edge& e = g.edges[k];
    if (!IsPosePose(e.kind)) continue;
    const int a = g.VertexIndex(e.from), b = g.VertexIndex(e.to);
    adj[a].emplace_back(static_cast<int>(k), b);
    adj[b].emplace_back(static_cast<int>(k), a);
  }
  return adj;
}

std::vector<char> CheckConnected(const Graph& g, int root) {
  const auto adj = Adjacency(g);
  std::vector<char> seen(g.vertices.size(), 0);
  std::queue<int> q;
  q.push(root);
  seen[root] = 1;
  while (!q.empty()) {
    const int a = q.front();
    q.pop();
    for (auto [k, b] : adj[a]) {
      if (!seen[b]) {
        seen[b] = 1;
        q.push(b);
      }
    }
  }
  for (size_t i = 0; i < g.vertices.size(); ++i) {
    BOXPLUS_CHECK(seen[i] || !IsPose(g.vertices[i].kind), Where(g, g.vertices[i].line),
                  "initialisation: pose vertex ", g.vertices[i].id,
                  " is not connected to the root vertex ", g.vertices[root].id,
                  " by pose-pose edges");
  }
  return seen;
}

}  // namespace

namespace {

const NamedEnum<InitMethod>& InitMethods() {
  static const NamedEnum<InitMethod> names(
      "initialisation", {{InitMethod::kFile, "file", {}},
                         {InitMethod::kSpanningTree, "spanning-tree", {"odometry"}},
                         {InitMethod::kChordal, "chordal", {}},
                         {InitMethod::kBest, "best", {}}});
  return names;
}

}  // namespace

InitMethod ParseInitMethod(const std::string& name) { return InitMethods().Parse(name); }

const char* InitMethodName(InitMethod method) { return InitMethods().Name(method).c_str(); }

InitMethod Initialize(Graph* g, InitMethod method, int root_id, const StartObjective& objective,
                      std::vector<Eigen::VectorXd>* other) {
  if (other) other->clear();
  switch (method) {
    case InitMethod::kFile:
      if (g->estimates_from_file) return InitMethod::kFile;
      InitializeSpanningTree(g, root_id);
      return InitMethod::kSpanningTree;
    case InitMethod::kSpanningTree:
      InitializeSpanningTree(g, root_id);
      return method;
    case InitMethod::kChordal:
      InitializeChordal(g, root_id);
      return method;
    case InitMethod::kBest:
      break;
  }
  BOXPLUS_CHECK(static_cast<bool>(objective), Where(*g),
                "initialisation 'best' needs an objective to compare starts by");
  const InitMethod file = Initialize(g, InitMethod::kFile, root_id);
  std::vector<Eigen::VectorXd> kept(g->vertices.size());
  for (size_t i = 0; i < kept.size(); ++i) kept[i] = g->vertices[i].estimate;
  const double at_file = objective(*g);
  try {
    InitializeChordal(g, root_id);
  } catch (const Error&) {
    // No relaxation to compare with (no pose-pose edge, disconnected, singular).
    for (size_t i = 0; i < kept.size(); ++i) g->vertices[i].estimate = std::move(kept[i]);
    return file;
  }
  const double at_chordal = objective(*g);
  // A non-finite objective at the file's start loses; at the chordal one it
  // loses too (std::isless is false for NaN).
  if (std::isless(at_chordal, at_file) || (!std::isfinite(at_file) && std::isfinite(at_chordal))) {
    if (other) *other = std::move(kept);
    return InitMethod::kChordal;
  }
  for (size_t i = 0; i < kept.size(); ++i) g->vertices[i].estimate = std::move(kept[i]);
  return file;
}

void InitializeSpanningTree(Graph* g, int root_id) {
  const int root = RootIndex(*g, root_id);
  const auto adj = Adjacency(*g);
  std::vector<char> done(g->vertices.size(), 0);
  std::vector<Eigen::Matrix4d> T(g->vertices.size());
  T[root] = ToMatrix(g->vertices[root].kind, g->vertices[root].estimate);
  done[root] = 1;
  std::queue<int> q;
  q.push(root);
  while (!q.empty()) {
    const int a = q.front();
    q.pop();
    for (auto [k, b] : adj[a]) {
      if (done[b]) continue;
      const io::Edge& e = g->edges[k];
      const Eigen::Matrix4d Z = EdgeMatrix(e);
      // Edge from→to: T_to = T_from · Z.
      T[b] = (g->VertexIndex(e.from) == a) ? Eigen::Matrix4d(T[a] * Z)
                                           : Eigen::Matrix4d(T[a] * Z.inverse());
      g->vertices[b].estimate = FromMatrix(g->vertices[b].kind, T[b]);
      g->vertices[b].has_estimate = true;
      done[b] = 1;
      q.push(b);
    }
  }
  CheckConnected(*g, root);
  PlaceLandmarks(g, done);
}

namespace {

struct PoseEdge {
  int k, i, j;  // edge index, vertex indices of its ends
};

// The rotations of the 2D relaxation as complex numbers, y_u = e^{iθ_u}: the
// residual of edge i→j with z = e^{iφ_ij} is y_j − z y_i (weight κ), so H is
// Hermitian n×n with H_ii += κ, H_jj += κ, H_ij = −κ z̄, H_ji = −κ z. The same
// least squares as the real system on the rows of R_u (whose D = 2 right-hand
// sides differ by a quarter turn), with a quarter of its non-zeros; the
// nearest rotation to y_u is y_u/|y_u|.
void ChordalRotations2D(const Graph& g, const std::vector<PoseEdge>& edges,
                        const std::vector<double>& kappa, const std::vector<int>& unk,
                        const Eigen::VectorXi& order, const Eigen::Matrix2d& R_root,
                        std::vector<Eigen::Matrix2d>* R) {
  using C = std::complex<double>;
  const int n = static_cast<int>(order.size());
  const C y_root(R_root(0, 0), R_root(1, 0));
  std::vector<Eigen::Triplet<C>> trip;
  trip.reserve(4 * edges.size());
  Eigen::VectorXcd rhs = Eigen::VectorXcd::Zero(n);
  for (const PoseEdge& pe : edges) {
    const double phi = g.edges[pe.k].measurement[2];
    const C z(std::cos(phi), std::sin(phi));
    const double kap = kappa[pe.k];
    const int bi = unk[pe.i] >= 0 ? order[unk[pe.i]] : -1;
    const int bj = unk[pe.j] >= 0 ? order[unk[pe.j]] : -1;
    if (bi >= 0) trip.emplace_back(bi, bi, kap);
    if (bj >= 0) trip.emplace_back(bj, bj, kap);
    if (bi >= 0 && bj >= 0) {
      trip.emplace_back(bi, bj, -kap * std::conj(z));
      trip.emplace_back(bj, bi, -kap * z);
    } else if (bj >= 0) {  // i is the root
      rhs[bj] += kap * z * y_root;
    } else if (bi >= 0) {  // j is the root
      rhs[bi] += kap * std::conj(z) * y_root;
    }
  }
  Eigen::SparseMatrix<C> H(n, n);
  H.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<C>, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(H);
  BOXPLUS_CHECK(ldlt.info() == Eigen::Success, SingularSystem(g, "rotation", kappa));
  const Eigen::VectorXcd y = ldlt.solve(rhs);
  BOXPLUS_CHECK(y.allFinite(), SingularSystem(g, "rotation", kappa));
  for (size_t i = 0; i < unk.size(); ++i) {
    if (unk[i] < 0) continue;
    const C yi = y[order[unk[i]]];
    const double r = std::abs(yi);
    const double c = r > 0.0 ? yi.real() / r : 1.0, s = r > 0.0 ? yi.imag() / r : 0.0;
    (*R)[i] << c, -s, s, c;
  }
}

// The chordal relaxation in dimension D (Carlone et al., ICRA 2015):
// rotations by linear least squares on their rows, projected onto SO(D),
// then translations by the weighted Laplacian.
//
// Both systems have the pattern of the pose graph (the rotation system with
// D×D blocks), so one fill-reducing ordering serves both: AMD on the n×n
// Laplacian, block-expanded for the rotations (ordering the Dn×Dn scalar
// system by itself took as long as factorising it).
// Each system is factorised once, in the AMD order built here: CHOLMOD's
// three analyses (sparse_cholesky.h) would cost more than they save on all
// but the largest graphs (torus3D 0.065 → 0.14 s, a 3D sphere of 10⁴ poses
// 0.15 → 0.34 s; 12.6 → 7.3 s at 10⁵ poses).
constexpr auto kOneSolve = internal::SparseCholesky::Orderings::kAsGiven;

template <int D>
void ChordalStart(Graph* g, int root) {
  using Mat = Eigen::Matrix<double, D, D>;
  // Unknown index of each pose (the root is eliminated).
  std::vector<int> unk(g->vertices.size(), -1);
  int n = 0;
  for (size_t i = 0; i < g->vertices.size(); ++i) {
    if (static_cast<int>(i) != root && IsPose(g->vertices[i].kind)) unk[i] = n++;
  }
  if (n == 0) return;
  const Eigen::Matrix4d T_root = ToMatrix(g->vertices[root].kind, g->vertices[root].estimate);
  const Mat R_root = T_root.topLeftCorner<D, D>();
  std::vector<PoseEdge> edges;
  edges.reserve(g->edges.size());
  std::vector<double> kappa(g->edges.size(), 0.0), tau(g->edges.size(), 0.0);
  for (size_t k = 0; k < g->edges.size(); ++k) {
    const io::Edge& e = g->edges[k];
    if (!IsPosePose(e.kind)) continue;
    edges.push_back({static_cast<int>(k), g->VertexIndex(e.from), g->VertexIndex(e.to)});
    const ChordalPrecisions precisions = ChordalPrecisionsOfInformation(e.information);
    kappa[k] = precisions.kappa;
    tau[k] = precisions.tau;
  }

  // Translations' Laplacian ‖t_j − t_i − R_i t_ij‖² τ: its values need no
  // rotation, so its ordering comes first.
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * edges.size());
  for (const PoseEdge& pe : edges) {
    const int ui = unk[pe.i], uj = unk[pe.j];
    const double w = tau[pe.k];
    if (ui >= 0) trip.emplace_back(ui, ui, w);
    if (uj >= 0) trip.emplace_back(uj, uj, w);
    if (ui >= 0 && uj >= 0) {
      trip.emplace_back(ui, uj, -w);
      trip.emplace_back(uj, ui, -w);
    }
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse_order;
  Eigen::AMDOrdering<int>()(L, inverse_order);
  // Position of unknown u in the ordering: order[u] (P L Pᵀ is factorised).
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> to_order =
      inverse_order.inverse();
  const Eigen::VectorXi& order = to_order.indices();
  // The Laplacian in that order, upper triangle, for the line search's
  // Cholesky (simplicial, or supernodal where the factor fills in).
  std::vector<Eigen::Triplet<double>> upper;
  upper.reserve(trip.size());
  for (const Eigen::Triplet<double>& t : trip) {
    const int r = order[t.row()], c = order[t.col()];
    if (r <= c) upper.emplace_back(r, c, t.value());
  }
  Eigen::SparseMatrix<double> L_ordered(n, n);
  L_ordered.setFromTriplets(upper.begin(), upper.end());

  std::vector<Mat> R(g->vertices.size(), Mat::Identity());
  R[root] = R_root;
  if constexpr (D == 2) {
    ChordalRotations2D(*g, edges, kappa, unk, order, R_root, &R);
  } else {
    // Rotations: unknown x_u = (row r of R_u)ᵀ ∈ Rᴰ for r = 0..D−1 (D right-hand
    // sides, one matrix), stored at block order[u]. Residual of edge i→j:
    // x_j − Zᵀ x_i, so H_ii += κ ZZᵀ = κI, H_jj += κI, H_ij = −κZ, H_ji = −κZᵀ.
    trip.clear();
    trip.reserve(edges.size() * 2 * (D + D * D));
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n * D, D);
    auto add_block = [&](int r, int c, const Mat& B) {  // its upper-triangle part
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b)
          if (B(a, b) != 0.0 && r * D + a <= c * D + b)
            trip.emplace_back(r * D + a, c * D + b, B(a, b));
    };
    for (const PoseEdge& pe : edges) {
      const io::Edge& e = g->edges[pe.k];
      const Mat Z = EdgeMatrix(e).topLeftCorner<D, D>();
      const double kap = kappa[pe.k];
      const int bi = unk[pe.i] >= 0 ? order[unk[pe.i]] : -1;
      const int bj = unk[pe.j] >= 0 ? order[unk[pe.j]] : -1;
      if (bi >= 0) add_block(bi, bi, kap * Mat::Identity());
      if (bj >= 0) add_block(bj, bj, kap * Mat::Identity());
      if (bi >= 0 && bj >= 0) {
        add_block(bi, bj, -kap * Z);
        add_block(bj, bi, -kap * Z.transpose());
      } else if (bj >= 0) {  // i is the root: x_i known (column r = row r of R_root)
        rhs.block<D, D>(bj * D, 0) += kap * Z.transpose() * R_root.transpose();
      } else if (bi >= 0) {  // j is the root
        rhs.block<D, D>(bi * D, 0) += kap * Z * R_root.transpose();
      }
    }
    Eigen::SparseMatrix<double> H(n * D, n * D);  // upper triangle
    H.setFromTriplets(trip.begin(), trip.end());
    // The line search's Cholesky: simplicial, or supernodal when the factor
    // fills in (a 3D sphere of 10⁵ poses took 88 s to initialise with the
    // simplicial factorisation alone, 12.6 s so).
    internal::SparseCholesky rotations(kOneSolve);
    rotations.Analyse(H);
    Eigen::MatrixXd X;
    BOXPLUS_CHECK(rotations.SolveUnshifted(H, rhs, &X), SingularSystem(*g, "rotation", kappa));
    for (size_t i = 0; i < g->vertices.size(); ++i) {
      if (unk[i] >= 0) R[i] = NearestRotation(Mat(X.block<D, D>(order[unk[i]] * D, 0).transpose()));
    }
  }

  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, D);  // rows in the order of the unknowns
  const Eigen::Matrix<double, 1, D> t_root = T_root.topRightCorner<D, 1>().transpose();
  for (const PoseEdge& pe : edges) {
    const io::Edge& e = g->edges[pe.k];
    const Eigen::Matrix<double, 1, D> c =
        (R[pe.i] * e.measurement.head<D>()).transpose();  // t_j − t_i ≈ c
    const double w = tau[pe.k];
    const int ui = unk[pe.i], uj = unk[pe.j];
    if (ui >= 0) {
      b.row(ui) -= w * c;
    } else {
      b.row(uj) += w * t_root;
    }
    if (uj >= 0) {
      b.row(uj) += w * c;
    } else {
      b.row(ui) += w * t_root;
    }
  }
  Eigen::MatrixXd b_ordered(n, D);
  for (int u = 0; u < n; ++u) b_ordered.row(order[u]) = b.row(u);
  internal::SparseCholesky translations(kOneSolve);
  translations.Analyse(L_ordered);
  Eigen::MatrixXd t_ordered;
  BOXPLUS_CHECK(translations.SolveUnshifted(L_ordered, b_ordered, &t_ordered),
                SingularSystem(*g, "translation", tau));
  Eigen::MatrixXd t(n, D);
  for (int u = 0; u < n; ++u) t.row(u) = t_ordered.row(order[u]);
  std::vector<char> done(g->vertices.size(), 0);
  for (size_t i = 0; i < g->vertices.size(); ++i) {
    if (unk[i] < 0) {
      done[i] = static_cast<int>(i) == root;
      continue;
    }
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<D, D>() = R[i];
    T.topRightCorner<D, 1>() = t.row(unk[i]).transpose();
    g->vertices[i].estimate = FromMatrix(g->vertices[i].kind, T);
    g->vertices[i].has_estimate = true;
    done[i] = 1;
  }
  PlaceLandmarks(g, done);
}

}  // namespace

void InitializeChordal(Graph* g, int root_id) {
  const int root = RootIndex(*g, root_id);
  CheckConnected(*g, root);
  if (g->dimension == 3) {
    ChordalStart<3>(g, root);
  } else {
    ChordalStart<2>(g, root);
  }
}

}  // namespace boxplus::slam
