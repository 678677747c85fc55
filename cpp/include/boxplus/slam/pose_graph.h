// A pose graph (g2o/TORO file) as a boxplus::Problem, and its chi2.
//
// Every vertex becomes a variable: SE2 poses (ambient [x, y, θ]), SE3 poses
// (ambient [p, qx, qy, qz, qw], tangent [δp, δθ] — translation first, ⊞ the
// compound R³ × SO(3)), 2D/3D points (Rⁿ). Every edge becomes a measurement
// with the file's information matrix:
//   EDGE_SE2 / EDGE2            → MakeRelativePose2D (factors/pose/relative_pose2d.h)
//   EDGE_SE3:QUAT / EDGE3       → MakeRelativePose3D in the chosen convention
//                                 (g2o's, or GTSAM's SE(3)-log; relative_pose3d.h)
//   both, convention kSESync    → MakeRelativePose2D/3DSESync (SE-Sync's chordal
//                                 objective; factors/pose/relative_pose_sesync.h)
//   EDGE_SE2_XY, EDGE_SE3_TRACKXYZ → MakePosePoint2D/3D (factors/pose/pose_point.h)
//   EDGE_SE2_BEARING_RANGE      → MakeBearingRange2D (factors/pose/bearing_range.h)
//   EDGE_SE2/SE3_OFFSET, EDGE_PRIOR_SE2, EDGE_SE3_PRIOR
//                               → MakeOffsetPose*/MakeOffsetPosePrior* (g2o's
//                                 error in every convention; offset_pose.h)
//   EDGE_SE3_TRACKXYZ (non-identity offset), EDGE_SE2_POINTXY_OFFSET,
//   EDGE_POINTXY(Z), EDGE_PRIOR_XY, EDGE_POINTXYZ_PRIOR, EDGE_PRIOR_SE2_XY,
//   EDGE_SE3_XYZ_PRIOR, EDGE_BEARING_SE2_XY
//                               → point_in_frame.h
//   EQUIV (TORO)                → a tight EDGE_SE2/SE3 (io/g2o.h)
// optionally wrapped in a robust loss ρ with a width (Huber, Cauchy, ...).
// The gauge: the vertices of the FIX lines are held constant, else the first
// pose vertex of the file, unless a full pose prior (EDGE_PRIOR_SE2,
// EDGE_SE3_PRIOR) fixes it already (as g2o decides; then gauge_vertex() = −1). The objective is Σ
// ρ(eᵀΩe) (chi2 without a robust loss; Ceres reports half of it as its cost).
//
// The problem is built in C++ in one pass (no per-edge call from Python), and
// Python/C++ code may extend it (problem(), AddEdge, AddVertex, Fix) before
// solving. Save() writes the file back with the solution, ids and order kept.
#pragma once

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <ceres/loss_function.h>

#include "boxplus/factors/pose/relative_pose3d.h"
#include "boxplus/io/g2o.h"
#include "boxplus/problem.h"
#include "boxplus/slam/load_report.h"

namespace boxplus::slam {

// Cost function of one edge, whitened by `noise` (the edge's information).
std::shared_ptr<ceres::CostFunction> MakeEdgeCost(const io::Edge& edge, const NoiseModel& noise,
                                                  PoseErrorConvention convention);

// eᵀΩe of one edge at the given vertex values (ambient layouts as above); for
// pose edges in the kSESync convention, ‖r‖² (the edge's term of SE-Sync's f).
double EdgeChi2(const io::Edge& edge, const double* from, const double* to,
                PoseErrorConvention convention);

// The solver settings for pose graphs, chosen from measurements on the
// standard data sets in both conventions (README, SLAM; bench/bench_slam.py):
// Levenberg–Marquardt that starts as Gauss–Newton (initial trust-region radius
// 1e16) and damps only after a failed step, with Levenberg's λI damping (as
// g2o's LM) on the unscaled Jacobian and up to 5 consecutive nonmonotonic
// steps. Gauss–Newton's iteration counts (4 on parking-garage instead of 29
// with Ceres' defaults) while keeping LM's safeguard on bad starts (MIT).
SolverOptions DefaultSolverOptions();

// The trust-region strategy for a pose graph of the given dimension (2 or 3),
// measured on the nine standard data sets from their files' estimates: for 2D
// graphs Powell's dogleg reaches the lowest objective any solver reaches (MIT,
// g2o convention: 476.30 against 770.66 for LM and g2o's Gauss–Newton, 526.33
// for g2o's LM) and equals LM elsewhere; for 3D graphs LM needs fewer
// iterations (parking-garage 4 vs 30) and ends lower after 100 on torus3D.
Method DefaultMethod(int dimension);

struct PoseGraphOptions {
  PoseErrorConvention convention = PoseErrorConvention::kG2o;
  std::string robust = "none";
  double robust_width = 1.0;
};

class PoseGraph {
 public:
  // Builds the problem from `graph` (its vertex estimates are the initial
  // values) and fixes the gauge.
  explicit PoseGraph(io::Graph graph, const PoseGraphOptions& options = {});

  Problem& problem() { return problem_; }
  // What LoadPoseGraph reported (empty for a graph built from an io::Graph).
  const LoadReport& load_report() const { return load_report_; }
  void set_load_report(LoadReport report) { load_report_ = std::move(report); }
  const io::Graph& graph() const { return graph_; }
  const PoseGraphOptions& options() const { return options_; }

  // Variable id of a vertex id; throws IndexError for an unknown id.
  int variable(int vertex_id) const;  // the pose if a pose and a landmark share the id
  // Variable id of graph().vertices[index] (a landmark whose id a pose shares).
  int variable_at(int vertex_index) const;
  int landmark_variable(int landmark_id) const;
  // Vertex ids, in the order of the variables (= file order of vertices).
  std::vector<int> vertex_ids() const;
  // The vertex held fixed for the gauge (first FIX id or first vertex; −1
  // when pose priors fix the gauge).
  int gauge_vertex() const { return gauge_vertex_; }
  void Fix(int vertex_id, bool fixed = true);
  // Holds exactly these vertices fixed (g2o's -gaugeId / -gaugeList),
  // releasing the FIX lines' and the default gauge; the first is
  // gauge_vertex(). Throws IndexError (nothing changed) for an unknown id.
  void SetGauge(const std::vector<int>& vertex_ids);

  // Adds a vertex / edge to both the graph (saved with it) and the problem;
  // returns the variable / measurement id. SE3 quaternions are normalised
  // (overflow-safe) and SE2 angles wrapped first; then everything is checked
  // (io::Graph::CheckVertex/CheckEdge) before anything changes, so a call
  // that throws leaves the graph and the problem unchanged.
  int AddVertex(const io::Vertex& vertex);
  int AddEdge(const io::Edge& edge);

  SolveSummary Solve(const SolverOptions& options = {});

  // Σ eᵀΩe over the graph's edges at the current values (no robust loss).
  double Chi2(PoseErrorConvention convention) const;
  double Chi2() const { return Chi2(options_.convention); }

  // Copies the current values into the graph's vertex estimates.
  void WriteBack();
  // WriteBack(), then io::WriteG2o.
  void Save(const std::string& path);

 private:
  void AddEdgeToProblem(const io::Edge& edge);
  io::Graph graph_;
  PoseGraphOptions options_;
  Problem problem_;
  std::vector<int> var_of_vertex_;  // index in graph_.vertices → variable id
  std::shared_ptr<ceres::LossFunction> loss_;
  int gauge_vertex_ = -1;
  LoadReport load_report_;
};

}  // namespace boxplus::slam
