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
// Landmarks are placed from their first observation (pose · z, or the
// bearing-range point). The root keeps its estimate. Vertices not connected to
// the root through pose–pose edges: boxplus::Error.
#pragma once

#include <string>

#include "boxplus/io/g2o.h"

namespace boxplus::slam {

enum class InitMethod { kFile, kSpanningTree, kChordal };

// "file", "spanning-tree" (or "odometry"), "chordal"; throws otherwise.
InitMethod ParseInitMethod(const std::string& name);

// root_id: the vertex held at its estimate (the gauge); -1 = first vertex.
void Initialize(io::Graph* graph, InitMethod method, int root_id = -1);
void InitializeSpanningTree(io::Graph* graph, int root_id = -1);
void InitializeChordal(io::Graph* graph, int root_id = -1);

}  // namespace boxplus::slam
