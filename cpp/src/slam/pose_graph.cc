#include "boxplus/slam/pose_graph.h"

#include "boxplus/loss.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/bearing_range.h"
#include "boxplus/factors/pose/chordal_relative_pose.h"
#include "boxplus/factors/pose/observed_point.h"
#include "boxplus/factors/pose/offset_pose.h"
#include "boxplus/factors/pose/point_in_frame.h"
#include "boxplus/factors/pose/relative_pose.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "boxplus/manifolds.h"

namespace boxplus::slam {

namespace {

// An edge's offset parameter in the ambient layout (SE2 [x, y, θ], SE3 [t,
// qxyzw]); the identity when the edge has none.
Eigen::VectorXd OffsetOrIdentity(const Eigen::VectorXd& offset, int ambient) {
  if (offset.size() == ambient) return offset;
  Eigen::VectorXd id = Eigen::VectorXd::Zero(ambient);
  if (ambient == 7) id[6] = 1.0;
  return id;
}

// The cost and the error of the edge kinds of offset_pose.h / point_in_frame.h.
std::shared_ptr<ceres::CostFunction> MakeG2oOffsetEdgeCost(const io::Edge& e,
                                                           const NoiseModel& noise) {
  const Eigen::VectorXd& z = e.measurement;
  switch (e.kind) {
    case io::EdgeKind::kSE2Offset:
      return MakeOffsetPose2D(z, OffsetOrIdentity(e.offset, 3), OffsetOrIdentity(e.offset_to, 3),
                              noise);
    case io::EdgeKind::kSE3Offset:
      return MakeOffsetPose3D(z, OffsetOrIdentity(e.offset, 7), OffsetOrIdentity(e.offset_to, 7),
                              noise);
    case io::EdgeKind::kSE2Prior:
      return MakeOffsetPosePrior2D(z, OffsetOrIdentity(Eigen::VectorXd(), 3), noise);
    case io::EdgeKind::kSE3Prior:
      return MakeOffsetPosePrior3D(z, OffsetOrIdentity(e.offset, 7), noise);
    case io::EdgeKind::kSE2PositionPrior:
      return MakePositionPrior(z, 3, noise);
    case io::EdgeKind::kSE3PositionPrior:
      return MakePositionPrior(z, 7, noise);
    case io::EdgeKind::kPoint2Prior:
    case io::EdgeKind::kPoint3Prior:
      return MakePositionPrior(z, static_cast<int>(z.size()), noise);
    case io::EdgeKind::kPoint2Point2:
    case io::EdgeKind::kPoint3Point3:
      return MakePointDifference(z, noise);
    case io::EdgeKind::kSE2Point2Offset:
      return MakePointInPose2D(z, OffsetOrIdentity(e.offset, 3), noise);
    case io::EdgeKind::kSE3Point3Offset:
      return MakePointInPose3D(z, OffsetOrIdentity(e.offset, 7), noise);
    case io::EdgeKind::kSE2Bearing:
      return MakeBearing2D(z[0], noise);
    default:
      throw Error("not an offset, prior or point edge");
  }
}

void G2oOffsetEdgeError(const io::Edge& e, const double* a, const double* b, double* err) {
  const double* z = e.measurement.data();
  const Eigen::VectorXd o3 = OffsetOrIdentity(e.offset, 3), o7 = OffsetOrIdentity(e.offset, 7);
  const Eigen::VectorXd t3 = OffsetOrIdentity(e.offset_to, 3),
                        t7 = OffsetOrIdentity(e.offset_to, 7);
  switch (e.kind) {
    case io::EdgeKind::kSE2Offset:
      return OffsetPoseError<2>(a, b, o3.data(), t3.data(), z, err);
    case io::EdgeKind::kSE3Offset:
      return OffsetPoseError<3>(a, b, o7.data(), t7.data(), z, err);
    case io::EdgeKind::kSE2Prior:
      return OffsetPoseError<2>(static_cast<const double*>(nullptr), a, nullptr,
                                OffsetOrIdentity(Eigen::VectorXd(), 3).data(), z, err);
    case io::EdgeKind::kSE3Prior:
      return OffsetPoseError<3>(static_cast<const double*>(nullptr), a, nullptr, o7.data(), z, err);
    case io::EdgeKind::kSE2PositionPrior:
    case io::EdgeKind::kPoint2Prior:
      return PositionPriorError<2>(a, z, err);
    case io::EdgeKind::kSE3PositionPrior:
    case io::EdgeKind::kPoint3Prior:
      return PositionPriorError<3>(a, z, err);
    case io::EdgeKind::kPoint2Point2:
      return PointDifferenceError<2>(a, b, z, err);
    case io::EdgeKind::kPoint3Point3:
      return PointDifferenceError<3>(a, b, z, err);
    case io::EdgeKind::kSE2Point2Offset:
      return PointInPoseError<2>(a, b, o3.data(), z, err);
    case io::EdgeKind::kSE3Point3Offset:
      return PointInPoseError<3>(a, b, o7.data(), z, err);
    case io::EdgeKind::kSE2Bearing:
      return Bearing2DError(a, b, z, err);
    default:
      throw Error("not an offset, prior or point edge");
  }
}

}  // namespace

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
    default:
      return MakeG2oOffsetEdgeCost(e, noise);
  }
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
  // On the stack (every error has at most 6 entries): the objective of a
  // start is summed over 10⁵–10⁶ edges.
  BOXPLUS_CHECK(n >= 1 && n <= 6, "edge error of size ", n);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> err(n);
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
    default:
      G2oOffsetEdgeError(e, a, b, err.data());
      break;
  }
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> weighted(n);
  weighted.noalias() = e.information * err;
  return err.dot(weighted);
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

// An edge's weight in a GNC copy: ρ(s) = w s, read at every evaluation so
// that the weights change between solves without rebuilding the problem.
class EdgeWeightLoss final : public ceres::LossFunction {
 public:
  explicit EdgeWeightLoss(const double* weight) : weight_(weight) {}
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = *weight_ * s;
    rho[1] = *weight_;
    rho[2] = 0.0;
  }

 private:
  const double* weight_;
};

}  // namespace

PoseGraph::PoseGraph(io::Graph graph, const PoseGraphOptions& options)
    : PoseGraph(std::move(graph), options, false) {}

PoseGraph::PoseGraph(io::Graph graph, const PoseGraphOptions& options, Weighted)
    : PoseGraph(std::move(graph), options, true) {}

PoseGraph::PoseGraph(io::Graph graph, const PoseGraphOptions& options, bool weighted)
    : graph_(std::move(graph)), options_(options) {
  if (weighted) {
    edge_weights_ = std::make_unique<double[]>(std::max<size_t>(graph_.edges.size(), 1));
    std::fill_n(edge_weights_.get(), graph_.edges.size(), 1.0);
  }
  loss_ = MakeLoss(options_.robust, options_.robust_width);
  // Measurement k < named_edges_ is edge k of the graph: its name is derived.
  problem_.SetMeasurementNamer([this](int id) {
    if (id >= named_edges_) return std::string();
    const io::Edge& e = graph_.edges[id];
    return EdgeName(e);
  });
  var_of_vertex_.reserve(graph_.vertices.size());
  problem_.Reserve(static_cast<int>(graph_.vertices.size()), static_cast<int>(graph_.edges.size()));
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
  // A full pose prior (EDGE_PRIOR_SE2, EDGE_SE3_PRIOR) fixes the gauge by
  // itself, as in g2o (SparseOptimizer::gaugeFreedom): no vertex is held then.
  const bool pose_prior = std::any_of(graph_.edges.begin(), graph_.edges.end(), [](const auto& e) {
    return e.kind == io::EdgeKind::kSE2Prior || e.kind == io::EdgeKind::kSE3Prior;
  });
  if (!fixed.empty()) {
    gauge_vertex_ = fixed.front();
  } else if (!pose_prior) {
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
  const int a = var_of_vertex_[graph_.EndIndex(e, 0)];
  const int b = var_of_vertex_[graph_.EndIndex(e, 1)];
  try {
    // One model per edge: the factor whitens with it and the problem keeps it
    // to un-whiten the edge's error. SE-Sync's chordal residual is whitened
    // by the model of its own error (chordal_relative_pose.h). The edge's
    // name is formatted only for a refusal (the second call throws again,
    // naming it): a string per edge was a tenth of a big graph's build.
    NoiseModel noise = [&] {
      try {
        return NoiseModel::Information(e.information, std::string());
      } catch (const Error&) {
        return NoiseModel::Information(e.information, EdgeName(e) + " information");
      }
    }();
    const bool chordal = options_.convention == PoseErrorConvention::kSESync &&
                         (e.kind == io::EdgeKind::kSE2 || e.kind == io::EdgeKind::kSE3);
    // The edges added in file order are named by the namer (no string each).
    const bool derived_name = problem_.num_measurements() == named_edges_;
    // The cost is made here, before the noise is moved into the call below
    // (the order in which a call's arguments are evaluated is unspecified).
    auto cost = MakeEdgeCost(e, noise, options_.convention);
    // A GNC copy weights each of the graph's edges (its own edges only).
    std::shared_ptr<ceres::LossFunction> loss = loss_;
    if (edge_weights_) {
      BOXPLUS_CHECK(problem_.num_measurements() < static_cast<int>(graph_.edges.size()),
                    "a weighted pose graph takes no edges beyond its graph's");
      loss = std::make_shared<EdgeWeightLoss>(&edge_weights_[problem_.num_measurements()]);
    }
    problem_.AddMeasurement(std::move(cost),
                            io::IsUnary(e.kind) ? std::vector<int>{a} : std::vector<int>{a, b},
                            chordal ? ChordalNoise(noise) : std::move(noise), std::move(loss),
                            derived_name ? std::string() : EdgeName(e));
    if (derived_name) ++named_edges_;
  } catch (const ParseError&) {
    throw;
  } catch (const Error& err) {
    // A factory's complaint about the measurement names the file's line.
    if (graph_.name.empty() || e.line <= 0) throw;
    throw ParseError(io::Escaped(graph_.name), e.line, EdgeName(e) + ": " + err.what());
  }
}

int PoseGraph::variable(int vertex_id) const {
  return var_of_vertex_[graph_.VertexIndex(vertex_id)];
}

int PoseGraph::variable_at(int vertex_index) const {
  BOXPLUS_CHECK_INDEX(vertex_index >= 0 && vertex_index < static_cast<int>(var_of_vertex_.size()),
                      "no vertex at index ", vertex_index);
  return var_of_vertex_[vertex_index];
}

int PoseGraph::landmark_variable(int landmark_id) const {
  auto it = graph_.landmark_index_of.find(landmark_id);
  BOXPLUS_CHECK_INDEX(it != graph_.landmark_index_of.end(), "no landmark with id ", landmark_id);
  return var_of_vertex_[it->second];
}

std::vector<int> PoseGraph::vertex_ids() const {
  std::vector<int> ids;
  ids.reserve(graph_.vertices.size());
  for (const auto& v : graph_.vertices) ids.push_back(v.id);
  return ids;
}

void PoseGraph::Fix(int vertex_id, bool fixed) { problem_.SetFixed(variable(vertex_id), fixed); }

void PoseGraph::SetGauge(const std::vector<int>& vertex_ids) {
  BOXPLUS_CHECK(!vertex_ids.empty(), "SetGauge: no vertex id");
  for (int id : vertex_ids) variable(id);  // every id exists before anything changes
  for (int id : graph_.FixedIds()) Fix(id, false);
  if (gauge_vertex_ >= 0) Fix(gauge_vertex_, false);
  for (int id : vertex_ids) Fix(id);
  gauge_vertex_ = vertex_ids.front();
}

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
    const double s = EdgeChi2(e, g.vertices[g.EndIndex(e, 0)].estimate.data(),
                              g.vertices[g.EndIndex(e, 1)].estimate.data(), options.convention);
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

int PoseGraph::FreeTangentSize() const {
  int size = 0;
  for (const int v : var_of_vertex_) {
    if (!problem_.IsFixed(v)) size += problem_.manifold(v).TangentSize();
  }
  return size;
}

double PoseGraph::DegreesOfFreedom() const {
  long dof = -FreeTangentSize();
  for (const io::Edge& e : graph_.edges) dof += io::ErrorSize(e.kind);
  return static_cast<double>(dof);
}

double PoseGraph::Chi2PerDof() const {
  const double dof = DegreesOfFreedom();
  return dof > 0 ? Chi2() / dof : std::numeric_limits<double>::quiet_NaN();
}

double PoseGraph::Chi2(PoseErrorConvention convention) const {
  double sum = 0.0;
  for (const io::Edge& e : graph_.edges) {
    sum += EdgeChi2(e, problem_.value(var_of_vertex_[graph_.EndIndex(e, 0)]),
                    problem_.value(var_of_vertex_[graph_.EndIndex(e, 1)]), convention);
  }
  return sum;
}

double PoseGraph::EdgeChi2At(int k) const {
  BOXPLUS_CHECK_INDEX(k >= 0 && k < static_cast<int>(graph_.edges.size()), "no edge at index ", k);
  const io::Edge& e = graph_.edges[k];
  return EdgeChi2(e, problem_.value(var_of_vertex_[graph_.EndIndex(e, 0)]),
                  problem_.value(var_of_vertex_[graph_.EndIndex(e, 1)]), options_.convention);
}

void PoseGraph::WriteBack() { WriteBackTo(&graph_); }

void PoseGraph::WriteBackTo(io::Graph* graph) const {
  BOXPLUS_CHECK(graph->vertices.size() == var_of_vertex_.size(),
                "WriteBackTo: ", graph->vertices.size(), " vertices for ", var_of_vertex_.size());
  for (size_t i = 0; i < graph->vertices.size(); ++i) {
    io::Vertex& v = graph->vertices[i];
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
