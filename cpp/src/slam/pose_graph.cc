#include "boxplus/slam/pose_graph.h"

#include "boxplus/loss.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/bearing_range.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/factors/pose/observed_point.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "boxplus/manifolds.h"

namespace boxplus::slam {

std::shared_ptr<ceres::CostFunction> MakeEdgeCost(const io::Edge& e, const NoiseModel& noise,
                                                  PoseErrorConvention convention) {
  const Eigen::VectorXd& z = e.measurement;
  switch (e.kind) {
    case io::EdgeKind::kSE2:
      return MakeRelativePose2D(z, noise, convention);
    case io::EdgeKind::kSE3:
      return MakeRelativePose3D(z, noise, convention);
    case io::EdgeKind::kSE2Point2:
      return MakeObservedPoint2D(z, noise);
    case io::EdgeKind::kSE3Point3:
      return MakeObservedPoint3D(z, noise);
    case io::EdgeKind::kSE2BearingRange:
      return MakeBearingRange2D(z, noise);
  }
  throw Error("unknown edge kind");
}

double EdgeChi2(const io::Edge& e, const double* a, const double* b,
                PoseErrorConvention convention) {
  const double* z = e.measurement.data();
  const bool pose_edge = e.kind == io::EdgeKind::kSE2 || e.kind == io::EdgeKind::kSE3;
  if (convention == PoseErrorConvention::kSESync && pose_edge) {
    const ChordalPrecisions p = ChordalPrecisionsOf(NoiseModel::Information(e.information));
    double r[12];
    const int n = e.kind == io::EdgeKind::kSE2 ? 6 : 12;
    if (n == 6) {
      ChordalRelativePose2DResidual(a, b, z, p, r);
    } else {
      ChordalRelativePose3DResidual(a, b, z, p, r);
    }
    return Eigen::Map<const Eigen::VectorXd>(r, n).squaredNorm();
  }
  const int n = io::ErrorSize(e.kind);
  Eigen::VectorXd err(n);
  switch (e.kind) {
    case io::EdgeKind::kSE2:
      WithErrorConvention(convention,
                          [&](auto c) { RelativePose2DError<decltype(c)>(a, b, z, err.data()); });
      break;
    case io::EdgeKind::kSE3:
      WithErrorConvention(convention,
                          [&](auto c) { RelativePose3DError<decltype(c)>(a, b, z, err.data()); });
      break;
    case io::EdgeKind::kSE2Point2:
      ObservedPointError<2>(a, b, z, err.data());
      break;
    case io::EdgeKind::kSE3Point3:
      ObservedPointError<3>(a, b, z, err.data());
      break;
    case io::EdgeKind::kSE2BearingRange:
      if (!BearingRange2DError(a, b, z, err.data())) return INFINITY;
      break;
  }
  return err.dot(e.information * err);
}

namespace {

std::string EdgeName(const io::Edge& e) {
  return "edge " + std::to_string(e.from) + "-" + std::to_string(e.to);
}

std::shared_ptr<const ceres::Manifold> ManifoldOf(io::VertexKind kind) {
  static const auto se2 = MakeManifold("SE2");
  static const auto se3 = MakeManifold("SE3");
  static const auto r2 = MakeManifold("Rn", 2);
  static const auto r3 = MakeManifold("Rn", 3);
  switch (kind) {
    case io::VertexKind::kSE2:
      return se2;
    case io::VertexKind::kSE3:
      return se3;
    case io::VertexKind::kPoint2:
      return r2;
    case io::VertexKind::kPoint3:
      return r3;
  }
  return nullptr;
}

}  // namespace

PoseGraph::PoseGraph(io::Graph graph, const PoseGraphOptions& options)
    : graph_(std::move(graph)), options_(options) {
  loss_ = MakeLoss(options_.robust, options_.robust_width);
  // Measurement k < named_edges_ is edge k of the graph: its name is derived.
  problem_.SetMeasurementNamer([this](int id) {
    if (id >= named_edges_) return std::string();
    const io::Edge& e = graph_.edges[id];
    return EdgeName(e);
  });
  var_of_vertex_.reserve(graph_.vertices.size());
  for (const io::Vertex& v : graph_.vertices) {
    try {
      var_of_vertex_.push_back(
          problem_.AddVariable(ManifoldOf(v.kind), v.estimate.data(), "x" + std::to_string(v.id)));
    } catch (const Error& err) {
      // An estimate the initialisation made non-finite names the vertex's line.
      if (graph_.name.empty() || v.line <= 0) throw;
      throw ParseError(io::Escaped(graph_.name), v.line,
                       "vertex " + std::to_string(v.id) + ": " + err.what());
    }
  }
  for (const io::Edge& e : graph_.edges) AddEdgeToProblem(e);
  const std::vector<int> fixed = graph_.FixedIds();
  for (int id : fixed) Fix(id);
  if (!fixed.empty()) {
    gauge_vertex_ = fixed.front();
  } else {
    for (const auto& rec : graph_.order) {
      if (rec.type != io::Graph::RecordType::kVertex) continue;
      const io::Vertex& v = graph_.vertices[rec.index];
      if (v.kind == io::VertexKind::kSE2 || v.kind == io::VertexKind::kSE3) {
        gauge_vertex_ = v.id;
        break;
      }
    }
    if (gauge_vertex_ >= 0) Fix(gauge_vertex_);
  }
}

void PoseGraph::AddEdgeToProblem(const io::Edge& e) {
  const int a = var_of_vertex_[graph_.VertexIndex(e.from)];
  const int b = var_of_vertex_[graph_.VertexIndex(e.to)];
  const std::string name = EdgeName(e);
  try {
    // One model per edge: the factor whitens with it and the problem keeps it
    // to un-whiten the edge's error. SE-Sync's chordal residual is whitened
    // by the model of its own error (chordal_relative_pose.h).
    const NoiseModel noise = NoiseModel::Information(e.information, name + " information");
    const bool chordal = options_.convention == PoseErrorConvention::kSESync &&
                         (e.kind == io::EdgeKind::kSE2 || e.kind == io::EdgeKind::kSE3);
    // The edges added in file order are named by the namer (no string each).
    const bool derived_name = problem_.num_measurements() == named_edges_;
    problem_.AddMeasurement(MakeEdgeCost(e, noise, options_.convention), {a, b},
                            chordal ? ChordalNoise(noise) : noise, loss_,
                            derived_name ? std::string() : name);
    if (derived_name) ++named_edges_;
  } catch (const ParseError&) {
    throw;
  } catch (const Error& err) {
    // A factory's complaint about the measurement names the file's line.
    if (graph_.name.empty() || e.line <= 0) throw;
    throw ParseError(io::Escaped(graph_.name), e.line, name + ": " + err.what());
  }
}

int PoseGraph::variable(int vertex_id) const {
  return var_of_vertex_[graph_.VertexIndex(vertex_id)];
}

std::vector<int> PoseGraph::vertex_ids() const {
  std::vector<int> ids;
  ids.reserve(graph_.vertices.size());
  for (const auto& v : graph_.vertices) ids.push_back(v.id);
  return ids;
}

void PoseGraph::Fix(int vertex_id, bool fixed) { problem_.SetFixed(variable(vertex_id), fixed); }

// Both validate completely (io::Graph::CheckVertex/CheckEdge, the cost's
// factory) before the graph or the problem changes: a failed call leaves both
// as they were, so chi2() and Save() never meet a half-added record.
int PoseGraph::AddVertex(const io::Vertex& vertex) {
  io::Vertex v = vertex;
  v.has_estimate = true;
  if (v.kind == io::VertexKind::kSE3 && v.estimate.size() == 7) {
    BOXPLUS_CHECK(NormalizeQuaternion(v.estimate.data() + 3, v.estimate.data() + 3), "vertex ",
                  v.id, ": quaternion is zero or not finite");
  }
  if (v.kind == io::VertexKind::kSE2 && v.estimate.size() == 3 && std::isfinite(v.estimate[2])) {
    v.estimate[2] = WrapAngleExact(v.estimate[2]);
  }
  graph_.CheckVertex(v);
  const int var =
      problem_.AddVariable(ManifoldOf(v.kind), v.estimate.data(), "x" + std::to_string(v.id));
  graph_.AddVertex(v);
  var_of_vertex_.push_back(var);
  return var;
}

int PoseGraph::AddEdge(const io::Edge& edge) {
  io::Edge e = edge;
  if (e.kind == io::EdgeKind::kSE3 && e.measurement.size() == 7) {
    BOXPLUS_CHECK(NormalizeQuaternion(e.measurement.data() + 3, e.measurement.data() + 3), "edge ",
                  e.from, " → ", e.to, ": quaternion is zero or not finite");
  }
  graph_.CheckEdge(e);
  AddEdgeToProblem(e);
  graph_.AddEdge(e);
  return problem_.num_measurements() - 1;
}

double Objective(const io::Graph& g, const PoseGraphOptions& options) {
  const std::shared_ptr<ceres::LossFunction> loss = MakeLoss(options.robust, options.robust_width);
  double sum = 0.0;
  for (const io::Edge& e : g.edges) {
    const double s = EdgeChi2(e, g.vertices[g.VertexIndex(e.from)].estimate.data(),
                              g.vertices[g.VertexIndex(e.to)].estimate.data(), options.convention);
    if (loss) {
      double rho[3];
      loss->Evaluate(s, rho);
      sum += rho[0];
    } else {
      sum += s;
    }
  }
  return sum;
}

SolverOptions DefaultSolverOptions() {
  SolverOptions o;
  o.method = Method::kGaussNewtonFallback;
  o.initial_trust_region_radius = 1e16;
  o.damping = Damping::kLevenberg;
  o.jacobi_scaling = false;
  o.use_nonmonotonic_steps = true;
  o.max_consecutive_nonmonotonic_steps = 5;
  return o;
}

void PoseGraph::set_second_start(std::vector<Eigen::VectorXd> estimates) {
  BOXPLUS_CHECK(estimates.empty() || estimates.size() == graph_.vertices.size(),
                "set_second_start: ", estimates.size(), " estimates for ", graph_.vertices.size(),
                " vertices");
  second_start_ = std::move(estimates);
}

double PoseGraph::Chi2PerDof() const {
  long dof = 0;
  for (const io::Edge& e : graph_.edges) dof += io::ErrorSize(e.kind);
  for (const int v : var_of_vertex_) {
    if (!problem_.IsFixed(v)) dof -= problem_.manifold(v).TangentSize();
  }
  return dof > 0 ? Chi2() / static_cast<double>(dof) : std::numeric_limits<double>::quiet_NaN();
}

SolveSummary PoseGraph::Solve(const SolverOptions& options) {
  SolveSummary first = problem_.Solve(options);
  const std::vector<Eigen::VectorXd> other = std::move(second_start_);
  second_start_.clear();
  if (other.empty() || !first.usable || first.termination == "interrupted") return first;
  const double per_dof = Chi2PerDof();
  if (!(per_dof > kImplausibleChi2PerDof)) return first;
  std::vector<Eigen::VectorXd> found(var_of_vertex_.size());
  for (size_t i = 0; i < found.size(); ++i) {
    const int v = var_of_vertex_[i];
    found[i] =
        Eigen::Map<const Eigen::VectorXd>(problem_.value(v), problem_.manifold(v).AmbientSize());
    if (!problem_.IsFixed(v)) problem_.SetValue(v, other[i].data());
  }
  SolveSummary second = problem_.Solve(options);
  const bool second_wins = second.usable && second.termination != "interrupted" &&
                           std::isless(second.final_cost, first.final_cost);
  if (!second_wins) {
    for (size_t i = 0; i < found.size(); ++i) problem_.SetValue(var_of_vertex_[i], found[i].data());
  }
  char why[200];
  std::snprintf(why, sizeof why,
                "chi2/dof %.3g > %g from the chordal start, so also solved from the file's "
                "estimate (%s)",
                per_dof, kImplausibleChi2PerDof, second_wins ? "lower: kept" : "not lower");
  SolveSummary out = second_wins ? second : first;
  out.initial_cost = first.initial_cost;
  out.iterations = first.iterations + second.iterations;
  out.time_s = first.time_s + second.time_s;
  out.message = std::string(why) + "; " + out.message;
  return out;
}

double PoseGraph::Chi2(PoseErrorConvention convention) const {
  double sum = 0.0;
  for (const io::Edge& e : graph_.edges) {
    sum += EdgeChi2(e, problem_.value(var_of_vertex_[graph_.VertexIndex(e.from)]),
                    problem_.value(var_of_vertex_[graph_.VertexIndex(e.to)]), convention);
  }
  return sum;
}

void PoseGraph::WriteBack() {
  for (size_t i = 0; i < graph_.vertices.size(); ++i) {
    io::Vertex& v = graph_.vertices[i];
    const double* x = problem_.value(var_of_vertex_[i]);
    std::copy(x, x + v.estimate.size(), v.estimate.data());
    v.has_estimate = true;
  }
}

void PoseGraph::Save(const std::string& path) {
  WriteBack();
  io::WriteG2o(path, graph_);
}

}  // namespace boxplus::slam
