#include "boxplus/slam/initialization.h"

#include <cmath>
#include <queue>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/manifolds/se2.h"
#include "boxplus/manifolds/se3.h"

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

InitMethod ParseInitMethod(const std::string& name) {
  if (name == "file") return InitMethod::kFile;
  if (name == "spanning-tree" || name == "odometry") return InitMethod::kSpanningTree;
  if (name == "chordal") return InitMethod::kChordal;
  if (name == "best") return InitMethod::kBest;
  throw Error("unknown initialisation '" + name +
              "' (expected file, spanning-tree, chordal or best)");
}

const char* InitMethodName(InitMethod method) {
  switch (method) {
    case InitMethod::kFile:
      return "file";
    case InitMethod::kSpanningTree:
      return "spanning-tree";
    case InitMethod::kChordal:
      return "chordal";
    case InitMethod::kBest:
      return "best";
  }
  return "?";
}

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

void InitializeChordal(Graph* g, int root_id) {
  const int root = RootIndex(*g, root_id);
  CheckConnected(*g, root);
  const int d = g->dimension == 3 ? 3 : 2;
  // Unknown index of each pose (the root is eliminated).
  std::vector<int> unk(g->vertices.size(), -1);
  int n = 0;
  for (size_t i = 0; i < g->vertices.size(); ++i) {
    if (static_cast<int>(i) != root && IsPose(g->vertices[i].kind)) unk[i] = n++;
  }
  if (n == 0) return;
  const Eigen::Matrix4d T_root = ToMatrix(g->vertices[root].kind, g->vertices[root].estimate);
  const Eigen::MatrixXd R_root = T_root.topLeftCorner(d, d);

  // Rotations: unknown x_i = (row k of R_i)ᵀ ∈ Rᵈ for k = 0..d−1 (d right-hand
  // sides, one matrix). Residual of edge i→j: x_j − Zᵀ x_i.
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n * d, d);
  std::vector<double> kappa(g->edges.size(), 0.0), tau(g->edges.size(), 0.0);
  auto add_block = [&](int r, int c, const Eigen::MatrixXd& B) {
    for (int a = 0; a < d; ++a)
      for (int b = 0; b < d; ++b)
        if (B(a, b) != 0.0) trip.emplace_back(r * d + a, c * d + b, B(a, b));
  };
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
  for (size_t k = 0; k < g->edges.size(); ++k) {
    const io::Edge& e = g->edges[k];
    if (!IsPosePose(e.kind)) continue;
    const int i = g->VertexIndex(e.from), j = g->VertexIndex(e.to);
    const Eigen::MatrixXd Z = EdgeMatrix(e).topLeftCorner(d, d);
    const ChordalPrecisions precisions = ChordalPrecisionsOfInformation(e.information);
    kappa[k] = precisions.kappa;
    tau[k] = precisions.tau;
    const double kap = kappa[k];
    // ‖x_j − Zᵀx_i‖²: H_ii += κ ZZᵀ = κI, H_jj += κI, H_ij = −κZ, H_ji = −κZᵀ.
    if (unk[i] >= 0) add_block(unk[i], unk[i], kap * I);
    if (unk[j] >= 0) add_block(unk[j], unk[j], kap * I);
    if (unk[i] >= 0 && unk[j] >= 0) {
      add_block(unk[i], unk[j], -kap * Z);
      add_block(unk[j], unk[i], -kap * Z.transpose());
    } else if (unk[j] >= 0) {  // i is the root: x_i known (column k = row k of R_root)
      rhs.block(unk[j] * d, 0, d, d) += kap * Z.transpose() * R_root.transpose();
    } else if (unk[i] >= 0) {  // j is the root
      rhs.block(unk[i] * d, 0, d, d) += kap * Z * R_root.transpose();
    }
  }
  Eigen::SparseMatrix<double> H(n * d, n * d);
  H.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  BOXPLUS_CHECK(ldlt.info() == Eigen::Success, SingularSystem(*g, "rotation", kappa));
  const Eigen::MatrixXd X = ldlt.solve(rhs);
  BOXPLUS_CHECK(X.allFinite(), SingularSystem(*g, "rotation", kappa));
  std::vector<Eigen::MatrixXd> R(g->vertices.size());
  R[root] = R_root;
  for (size_t i = 0; i < g->vertices.size(); ++i) {
    if (unk[i] < 0) continue;
    const Eigen::MatrixXd M = X.block(unk[i] * d, 0, d, d).transpose();  // rows of R_i
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::MatrixXd D = Eigen::MatrixXd::Identity(d, d);
    D(d - 1, d - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
    R[i] = svd.matrixU() * D * svd.matrixV().transpose();
  }

  // Translations: ‖t_j − t_i − R_i t_ij‖² τ; the Laplacian, d right-hand sides.
  trip.clear();
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, d);
  const Eigen::RowVectorXd t_root = T_root.topRightCorner(d, 1).transpose();
  for (size_t k = 0; k < g->edges.size(); ++k) {
    const io::Edge& e = g->edges[k];
    if (!IsPosePose(e.kind)) continue;
    const int i = g->VertexIndex(e.from), j = g->VertexIndex(e.to);
    const Eigen::RowVectorXd c = (R[i] * e.measurement.head(d)).transpose();  // t_j − t_i ≈ c
    const double w = tau[k];
    if (unk[i] >= 0) {
      trip.emplace_back(unk[i], unk[i], w);
      b.row(unk[i]) -= w * c;
    } else {
      b.row(unk[j]) += w * t_root;
    }
    if (unk[j] >= 0) {
      trip.emplace_back(unk[j], unk[j], w);
      b.row(unk[j]) += w * c;
    } else {
      b.row(unk[i]) += w * t_root;
    }
    if (unk[i] >= 0 && unk[j] >= 0) {
      trip.emplace_back(unk[i], unk[j], -w);
      trip.emplace_back(unk[j], unk[i], -w);
    }
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> lldlt(L);
  BOXPLUS_CHECK(lldlt.info() == Eigen::Success, SingularSystem(*g, "translation", tau));
  const Eigen::MatrixXd t = lldlt.solve(b);
  BOXPLUS_CHECK(t.allFinite(), SingularSystem(*g, "translation", tau));
  std::vector<char> done(g->vertices.size(), 0);
  for (size_t i = 0; i < g->vertices.size(); ++i) {
    if (unk[i] < 0) {
      done[i] = static_cast<int>(i) == root;
      continue;
    }
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner(d, d) = R[i];
    T.topRightCorner(d, 1) = t.row(unk[i]).transpose();
    g->vertices[i].estimate = FromMatrix(g->vertices[i].kind, T);
    g->vertices[i].has_estimate = true;
    done[i] = 1;
  }
  PlaceLandmarks(g, done);
}

}  // namespace boxplus::slam
