// Strict reader and writer of pose-graph files: g2o and TORO.
//
// g2o tags read (one record per line, '#' starts a comment):
//   VERTEX_SE2 id x y θ                     VERTEX_XY id x y
//   VERTEX_SE3:QUAT id x y z qx qy qz qw    VERTEX_TRACKXYZ id x y z
//   EDGE_SE2 i j dx dy dθ  I(6)             EDGE_SE2_XY i j x y  I(3)
//   EDGE_SE3:QUAT i j dx dy dz qx qy qz qw  I(21)
//   EDGE_SE3_TRACKXYZ i j offset_id x y z   I(6)   (offset must be 0 or absent
//                                                   PARAMS_SE3OFFSET: identity)
//   EDGE_SE2_BEARING_RANGE i j bearing range  I(3)  (boxplus extension, 2D
//                                                   Victoria Park style: the
//                                                   landmark j seen from pose i)
//   FIX id [id ...]
// TORO tags read: VERTEX2 id x y θ, EDGE2 i j dx dy dθ I11 I12 I22 I33 I13 I23,
//   VERTEX3 id x y z roll pitch yaw, EDGE3 i j dx dy dz roll pitch yaw I(21).
// I(k) is the upper triangle of the information matrix, row by row, in the
// order of the measurement's error vector: g2o SE2 [x, y, θ]; SE3
// [x, y, z, qx, qy, qz] (translation first, then the rotation — the same order
// as boxplus' SE(3) tangent); points [x, y(, z)]; bearing-range [b, r]. TORO
// 3D rotations are Euler angles R = Rz(yaw)·Ry(pitch)·Rx(roll); their
// information is used as the information of the rotation part as is.
//
// Quaternions are stored [x, y, z, w] and normalised when read (scaled by the
// largest component first: [0, 0, 0, 1e200] is the identity); a quaternion of
// zero norm is an error. SE2 angles are wrapped into [−π, π) exactly (1e16
// too). TORO Euler angles at pitch ±π/2 are written back as the same rotation.
// Bytes outside printable ASCII are quoted in messages as \xNN.
//
// Every malformed line (unknown tag, too few or too many numbers, a
// non-numeric field, an edge to a missing vertex, a duplicate vertex id, an
// information matrix that is not positive definite, a negative range) throws
// boxplus::ParseError naming the file and the 1-based line. Two switches relax
// this explicitly, never silently: `skip_unknown_tags` skips unknown tags and
// counts them in the report, `repair_information` replaces an indefinite
// information matrix by the nearest positive-definite one (eigenvalues
// clamped to 1e-9·max|λ|) and counts the repairs.
//
// Files without any VERTEX line (CSAIL, manhattan) are accepted: the vertices
// are created from the edges with `has_estimate = false`, and the caller
// initialises them (boxplus::slam::InitializeSpanningTree). When the file does
// have vertices, every edge must name existing ones.
//
// Writing keeps every record in its original order, with its original ids and
// tag family (g2o or TORO); vertex estimates are written as they are in the
// graph (update them from a solution first), measurements and information
// matrices as read.
#pragma once

#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace boxplus::io {

enum class VertexKind { kSE2, kSE3, kPoint2, kPoint3 };
enum class EdgeKind {
  kSE2,             // EDGE_SE2 / EDGE2: relative pose, SE2 → SE2
  kSE3,             // EDGE_SE3:QUAT / EDGE3: relative pose, SE3 → SE3
  kSE2Point2,       // EDGE_SE2_XY: landmark position in the pose frame
  kSE3Point3,       // EDGE_SE3_TRACKXYZ
  kSE2BearingRange  // EDGE_SE2_BEARING_RANGE
};

// Ambient size of a vertex estimate: SE2 3 [x, y, θ], SE3 7 [p, qxyzw],
// points 2 or 3.
int AmbientSize(VertexKind kind);
// Size of the measurement's error vector (= information matrix size).
int ErrorSize(EdgeKind kind);
// Size of the stored measurement (SE3: 7, [t, qxyzw]).
int MeasurementSize(EdgeKind kind);

struct Vertex {
  int id = 0;
  VertexKind kind = VertexKind::kSE2;
  Eigen::VectorXd estimate;  // ambient layout, see AmbientSize
  bool has_estimate = true;  // false when the file had no VERTEX line
  bool toro = false;         // written back with the TORO tag
  int line = 0;
};

struct Edge {
  EdgeKind kind = EdgeKind::kSE2;
  int from = 0, to = 0;         // vertex ids as in the file
  Eigen::VectorXd measurement;  // SE2 [x, y, θ]; SE3 [t, qxyzw]; points; [b, r]
  Eigen::MatrixXd information;  // full symmetric, error order (see above)
  int param = 0;                // EDGE_SE3_TRACKXYZ offset parameter id
  bool toro = false;
  int line = 0;
};

// One file: vertices, edges, FIX lines and the order they came in.
struct Graph {
  enum class RecordType { kVertex, kEdge, kFix, kParam };
  struct Record {
    RecordType type;
    int index;  // into vertices, edges, fixed or params
  };
  std::vector<Vertex> vertices;
  std::vector<Edge> edges;
  std::vector<std::vector<int>> fixed;  // each FIX line's ids
  std::vector<std::string> params;      // PARAMS_* lines, verbatim
  std::vector<Record> order;
  std::unordered_map<int, int> index_of;  // vertex id → index in vertices
  int dimension = 0;                      // 2 or 3 (of the poses), 0 if none
  bool estimates_from_file = true;        // false if vertices were created from edges
  std::string name;                       // the file it was read from (for messages)

  // Index into `vertices`; throws boxplus::IndexError for an unknown id.
  int VertexIndex(int id) const;
  // Ids of every FIX line, in order.
  std::vector<int> FixedIds() const;
  // Throw boxplus::Error (IndexError for an unknown id) unless the vertex /
  // edge can be added: a new id, sizes of its kind, finite values, unit
  // quaternions, a pose of the graph's dimension; an edge between existing
  // vertices of the kinds it connects, a non-negative range, a positive-
  // definite information. They never change the graph.
  void CheckVertex(const Vertex& v) const;
  void CheckEdge(const Edge& e) const;
  // Appends a vertex / edge (in memory; written at the end of the file), after
  // CheckVertex / CheckEdge: a failed call leaves the graph unchanged.
  int AddVertex(const Vertex& v);
  int AddEdge(const Edge& e);
};

struct ReadOptions {
  bool skip_unknown_tags = false;
  bool repair_information = false;
};

struct ReadReport {
  int lines = 0;
  int unknown_skipped = 0;
  std::map<std::string, int> unknown_tags;  // tag → count
  int repaired_information = 0;
  std::vector<int> repaired_lines;
  // One human-readable warning per kind of event, with counts ("" if none).
  std::string Warnings(const std::string& path) const;
};

// Reads a g2o or TORO file (the tags decide; they may be mixed). Throws
// ParseError(file, line, what) on malformed input, boxplus::Error if the file
// cannot be opened.
Graph ReadG2o(const std::string& path, const ReadOptions& options = {},
              ReadReport* report = nullptr);
// Parses text as if it were the content of a file named `name`.
Graph ParseG2o(const std::string& text, const std::string& name, const ReadOptions& options = {},
               ReadReport* report = nullptr);

// Writes the graph in its original order and tags (values with 17
// significant digits). Throws boxplus::Error if the file cannot be written.
void WriteG2o(const std::string& path, const Graph& graph);
std::string FormatG2o(const Graph& graph);

// Whether an edge of this kind connects vertices of kinds a → b.
bool ConnectsKinds(EdgeKind edge, VertexKind a, VertexKind b);

// Text with every byte outside printable ASCII written as \xNN: what error
// messages quote from a file (which may hold any bytes) stays valid text.
std::string Escaped(const std::string& text);

// Checks that `info` is symmetric positive definite (Cholesky succeeds).
bool IsPositiveDefinite(const Eigen::MatrixXd& info);
// Nearest symmetric positive-definite matrix in the Frobenius norm with
// eigenvalues at least 1e-9·max|λ|. Throws if `info` is zero (CanRepair).
bool CanRepair(const Eigen::MatrixXd& info);
Eigen::MatrixXd NearestPositiveDefinite(const Eigen::MatrixXd& info);

}  // namespace boxplus::io
