// Initial estimates for pose graphs, written into the graph's vertices.
//
// kFile          the file's VERTEX estimates (files without vertices fall
//                back to kSpanningTree).
// kSpanningTree  breadth-first spanning tree of the pose–pose edges from the
//                root (the gauge vertex), composing measurements:
//                x_j = x_i · z (edge i→j) or x_i = x_j · z⁻¹.
// kChordal       global rotation initialisation (Carlone et al., ICRA 2015):
//                rotations by the chordal relaxation
//                  min Σ κᵢⱼ ‖R_j − R_i Z_ij‖²_F   (R_root fixed),
//                a sparse linear least-squares problem, each solution
//                projected to SO(d) (SVD); then translations by linear least
//                squares  min Σ τᵢⱼ ‖t_j − t_i − R_i t_ij‖²  (t_root fixed).
//                Weights as SE-Sync: 3D κ = 3 / (2 tr(Ω_R⁻¹)), τ = 3 / tr(Ω_t⁻¹);
//                2D κ = Ω_θθ, τ = 2 / tr(Ω_t⁻¹).
// kBest         the better start, by the problem's objective, of the file's
//                estimate (kFile) and kChordal: the chordal relaxation is
//                close to the optimum when the noise is moderate and recovers
//                from odometry that drifted far ("bignoise"), while a file that
//                holds an optimised graph already is better than any
//                relaxation. Measured on the generated benchmark suite
//                (bench/bench_pose_graph_suite.py, README "Pose graphs"). If
//                the chordal relaxation cannot be built (no pose–pose edges, a
//                singular system) the file's estimate is kept.
// Landmarks are placed from their first observation (pose · z, or the
// bearing-range point). The root keeps its estimate. Vertices not connected to
// the root through pose–pose edges: boxplus::Error.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "boxplus/io/g2o.h"

namespace boxplus::slam {

enum class InitMethod { kFile, kSpanningTree, kChordal, kBest };

// "file", "spanning-tree" (or "odometry"), "chordal", "best"; throws otherwise.
InitMethod ParseInitMethod(const std::string& name);
// The name ParseInitMethod reads ("file", "spanning-tree", "chordal", "best").
const char* InitMethodName(InitMethod method);

// The objective kBest compares starts by (lower is better), evaluated at the
// graph's vertex estimates; e.g. slam::Objective (pose_graph.h).
using StartObjective = std::function<double(const io::Graph&)>;

// root_id: the vertex held at its estimate (the gauge); -1 = first vertex.
// Returns the start that was used: `method`, except kBest (kFile or kChordal,
// whichever has the lower objective) and kFile on a file without vertex
// estimates (kSpanningTree). kBest needs `objective`; when it chose kChordal
// and `other` is given, the file's start is left there (vertex order), else
// `other` is cleared.
InitMethod Initialize(io::Graph* graph, InitMethod method, int root_id = -1,
                      const StartObjective& objective = {},
                      std::vector<Eigen::VectorXd>* other = nullptr);
void InitializeSpanningTree(io::Graph* graph, int root_id = -1);
void InitializeChordal(io::Graph* graph, int root_id = -1);

}  // namespace boxplus::slam
