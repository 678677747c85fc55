// The second pass of the strict g2o/TORO reader (io/g2o.h): the graph as it is
// built, line by line, and one parser per record tag, found through the one
// tag table (g2o_tags.cc) that also names the writer's tags, --list-types'
// list and the fuzzer's tags.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "boxplus/io/g2o.h"
#include "g2o_lines.h"

namespace boxplus::io::detail {

inline int PoseDimension(VertexKind k) {
  return k == VertexKind::kSE2 ? 2 : k == VertexKind::kSE3 ? 3 : 0;
}

inline bool IsPoseKind(VertexKind k) { return PoseDimension(k) != 0; }

// The id range a vertex of this kind is numbered in.
inline const std::unordered_map<int, int>& RangeOf(const Graph& g, VertexKind k) {
  return IsPoseKind(k) ? g.index_of : g.landmark_index_of;
}

// A graph as the reader builds it: the records so far, and what the end of
// the file needs (the FIX lines to check, the EQUIVs to resolve).
class GraphBuilder {
 public:
  struct Equiv {
    int a, b, line;
    size_t record;  // its place in Graph::order
  };

  GraphBuilder(const std::string& name, const ReadOptions& options, ReadReport* report)
      : options(options), report(*report) {
    graph.name = name;
  }

  // Appends a vertex read from the line lp; a duplicate id or a mix of 2D and
  // 3D poses fails naming the line.
  void AddVertex(const LineParser& lp, VertexKind kind, Eigen::VectorXd estimate, bool toro);
  // Fills an edge's common fields, checks (and with the repair option repairs)
  // its information and appends it; returns it for the caller's extra fields.
  Edge& AddEdge(const LineParser& lp, EdgeKind kind, int from, int to, Eigen::VectorXd z,
                Eigen::MatrixXd information, bool toro, int param = 0);
  // A PARAMS_* line: the offset by id, and the line kept for the writer.
  void DefineOffset(const LineParser& lp, int id, Eigen::VectorXd value);
  // The offset of parameter id for an edge: identity (empty) when the id has
  // no PARAMS line and `lenient` (EDGE_SE3_TRACKXYZ), else the line must exist
  // and be of the edge's dimension.
  Eigen::VectorXd OffsetFor(const LineParser& lp, int id, int dimension, bool lenient) const;

  Graph graph;
  const ReadOptions& options;
  ReadReport& report;
  int line = 0;
  bool any_vertex_line = false;
  std::vector<int> fix_lines;
  std::vector<Equiv> equivs;
};

// Reads the record on line lp into builder; false when its tag is unknown.
bool ReadRecord(GraphBuilder& builder, const LineParser& lp);

}  // namespace boxplus::io::detail
