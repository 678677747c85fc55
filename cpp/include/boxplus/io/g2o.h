// Strict reader and writer of pose-graph files: g2o and TORO.
//
// g2o tags read (one record per line, '#' starts a comment); the tags and
// their layouts are those g2o registers in types_slam2d.cpp / types_slam3d.cpp
// (the maths of each edge: factors/pose/*.h, as g2o's computeError):
//   VERTEX_SE2 id x y θ                     VERTEX_XY id x y
//   VERTEX_SE3:QUAT id x y z qx qy qz qw    VERTEX_TRACKXYZ id x y z
//   EDGE_SE2 i j dx dy dθ  I(6)             EDGE_SE2_XY i j x y  I(3)
//   EDGE_SE3:QUAT i j dx dy dz qx qy qz qw  I(21)
//   EDGE_SE3_TRACKXYZ i j p x y z  I(6)     (p: a PARAMS_SE3OFFSET id; an id
//                                            without a PARAMS line is the
//                                            identity, as before)
//   PARAMS_SE2OFFSET p x y θ                PARAMS_SE3OFFSET p x y z qx qy qz qw
//   EDGE_SE2_OFFSET i j p q dx dy dθ I(6)   EDGE_SE3_OFFSET i j p q dx..qw I(21)
//   EDGE_PRIOR_SE2 i x y θ I(6)             EDGE_SE3_PRIOR i p x y z qx..qw I(21)
//   EDGE_PRIOR_SE2_XY i x y I(3)            EDGE_SE3_XYZ_PRIOR i p x y z I(6)
//   EDGE_PRIOR_XY i x y I(3)                EDGE_POINTXYZ_PRIOR i x y z I(6)
//   EDGE_POINTXY i j dx dy I(3)             EDGE_POINTXYZ i j dx dy dz I(6)
//   EDGE_SE2_POINTXY_OFFSET i j p x y I(3)  EDGE_BEARING_SE2_XY i j bearing I(1)
//   EDGE_SE2_BEARING_RANGE i j bearing range  I(3)  (boxplus extension, 2D
//                                                   Victoria Park style: the
//                                                   landmark j seen from pose i)
//   FIX id [id ...]
// Offset parameters (p, q) must be defined by a PARAMS line before the edge
// that uses them (as g2o resolves them when it reads the edge).
// TORO tags read (TORO's posegraph2/3.cpp): VERTEX2 (alias VERTEX) id x y θ,
// EDGE2 (alias EDGE) i j dx dy dθ I11 I12 I22 I33 I13 I23, VERTEX3 id x y z
// roll pitch yaw, EDGE3 i j dx dy dz roll pitch yaw I(21) — or without I(21):
// the identity information, as GTSAM's loader assumes (one warning per file;
// written back without it). TORO has no landmark lines; GTSAM's 2D landmark
// files (cityTrees_reduced_1k, victoriaPark_reduced_1k) have LANDMARK2 i j x
// y I11 I12 I22: pose i observes landmark j at (x, y) in its frame, with
// that information, i.e. EDGE_SE2_XY (landmark ids are their own namespace),
// written back as LANDMARK2.
// EQUIV i j (TORO): poses i and j are the same place. TORO collapses the edge
// between them (merges j into i through that edge, taking it as exact); here
// both poses stay variables and EQUIV adds a tight relative-pose constraint
// i → j: the measurement of an edge between them (oriented i → j) if there is
// one, else the identity ("the same pose"), with the information 1e6·I
// (σ = 1e-3 in metres and radians). A tight edge keeps the problem a plain sum
// of squares (merging would rewrite every factor of j), and the solution
// agrees with TORO's collapse to that σ. Written back as the EQUIV line.
// Id ranges: poses (VERTEX_SE2/SE3, VERTEX2/3) and landmarks (VERTEX_XY,
// VERTEX_TRACKXYZ) are numbered in two ranges: a pose and a landmark may have
// the same id (as GTSAM's writeG2o writes landmarks L(j) with their index j).
// The vertex tag says which range an id is in, and an edge's tag says which
// kind each of its ends is, so the reading is unambiguous; in one range an id
// is still unique. FIX and Graph::VertexIndex name the pose if both exist.
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

#include <functional>
#include <istream>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace boxplus::io {

enum class VertexKind { kSE2, kSE3, kPoint2, kPoint3 };
enum class EdgeKind {
  kSE2,               // EDGE_SE2 / EDGE2: relative pose, SE2 → SE2
  kSE3,               // EDGE_SE3:QUAT / EDGE3: relative pose, SE3 → SE3
  kSE2Point2,         // EDGE_SE2_XY: landmark position in the pose frame
  kSE3Point3,         // EDGE_SE3_TRACKXYZ
  kSE2BearingRange,   // EDGE_SE2_BEARING_RANGE
  kSE2Offset,         // EDGE_SE2_OFFSET: relative pose of two sensor frames
  kSE3Offset,         // EDGE_SE3_OFFSET
  kSE2Prior,          // EDGE_PRIOR_SE2: unary, the pose
  kSE3Prior,          // EDGE_SE3_PRIOR: unary, the pose of a sensor on it
  kSE2PositionPrior,  // EDGE_PRIOR_SE2_XY: unary, the pose's translation
  kSE3PositionPrior,  // EDGE_SE3_XYZ_PRIOR
  kPoint2Prior,       // EDGE_PRIOR_XY: unary, a 2D point
  kPoint3Prior,       // EDGE_POINTXYZ_PRIOR
  kPoint2Point2,      // EDGE_POINTXY: a point seen from a point (difference)
  kPoint3Point3,      // EDGE_POINTXYZ
  kSE2Point2Offset,   // EDGE_SE2_POINTXY_OFFSET: landmark in a sensor frame
  kSE3Point3Offset,   // EDGE_SE3_TRACKXYZ with a non-identity offset
  kSE2Bearing         // EDGE_BEARING_SE2_XY: bearing only
};

// Whether the edge names one vertex (a prior): then Edge::to == Edge::from.
bool IsUnary(EdgeKind kind);
// Whether end 0 (from) / 1 (to) of an edge of this kind is a pose (SE2/SE3)
// rather than a landmark: it is looked up in that id range.
bool EndIsPose(EdgeKind kind, int end);

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
  int param = 0;                // offset parameter id of the (first) sensor frame
  int param_to = 0;             // EDGE_SE2/SE3_OFFSET: that of the second
  // The parameters' values in the ambient layout (SE2 [x, y, θ], SE3 [t,
  // qxyzw]), filled when read; empty for the identity / no parameter.
  Eigen::VectorXd offset, offset_to;
  bool equiv = false;                 // a TORO EQUIV line (see above)
  bool identity_information = false;  // EDGE3 without I(21): written without
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
  std::unordered_map<int, int> index_of;           // pose id → index in vertices
  std::unordered_map<int, int> landmark_index_of;  // landmark id → index
  // Offset parameters by id: [x, y, θ] (PARAMS_SE2OFFSET) or [t, qxyzw].
  std::map<int, Eigen::VectorXd> offsets;
  int dimension = 0;                // 2 or 3 (of the poses), 0 if none
  bool estimates_from_file = true;  // false if vertices were created from edges
  std::string name;                 // the file it was read from (for messages)

  // Index into `vertices` (the pose if a pose and a landmark share the id);
  // throws boxplus::IndexError for an unknown id.
  int VertexIndex(int id) const;
  // Index of end 0 (from) or 1 (to) of an edge, in the id range its kind says.
  int EndIndex(const Edge& e, int end) const;
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
  int AddVertex(Vertex v);
  int AddEdge(const Edge& e);
};

// Progress of a read: lines and bytes parsed so far, of bytes_total.
struct ReadProgress {
  long long lines = 0;
  size_t bytes = 0, bytes_total = 0;
};

struct ReadOptions {
  bool skip_unknown_tags = false;
  bool repair_information = false;
  // Called every `progress_lines` lines (never if empty): the caller decides
  // what to show and when (boxplus-g2o: a line on stderr about once a second).
  std::function<void(const ReadProgress&)> on_progress;
  int progress_lines = 1 << 16;
};

struct ReadReport {
  int lines = 0;
  int unknown_skipped = 0;
  std::map<std::string, int> unknown_tags;  // tag → count
  int repaired_information = 0;
  std::vector<int> repaired_lines;
  int identity_information = 0;  // EDGE3 lines without information
  int first_identity_line = 0;
  int equiv = 0;  // EQUIV lines
  // One human-readable warning per kind of event, with counts ("" if none).
  std::string Warnings(const std::string& path) const;
};

// The longest line a reader accepts: no record comes near it (EDGE_SE3:QUAT
// with its 21 information entries is under 1 kB); a longer line, or a NUL byte,
// is binary data, refused at once with its line before the rest is read.
constexpr size_t kMaxLineBytes = size_t{1} << 20;

// Reads a g2o or TORO file (the tags decide; they may be mixed). Throws
// ParseError(file, line, what) on malformed input, boxplus::Error if the file
// cannot be opened. Memory is bounded by the input's structure: binary data
// (a NUL byte, a line beyond kMaxLineBytes) in the first megabyte, or anywhere
// in a stream (a pipe, /dev/zero), ends the read there; messages quote at most
// 40 bytes of a field.
Graph ReadG2o(const std::string& path, const ReadOptions& options = {},
              ReadReport* report = nullptr);
// Reads a whole stream (standard input) as text, with the checks of ReadG2o.
std::string ReadTextStream(std::istream& in, const std::string& name);
// Parses text as if it were the content of a file named `name`.
Graph ParseG2o(const std::string& text, const std::string& name, const ReadOptions& options = {},
               ReadReport* report = nullptr);

// Writes the graph in its original order and tags (values with 17
// significant digits). Throws boxplus::Error if the file cannot be written.
// Written atomically (io/atomic_file.h): a failed write keeps the previous file.
void WriteG2o(const std::string& path, const Graph& graph);
std::string FormatG2o(const Graph& graph);

// Whether an edge of this kind connects vertices of kinds a → b.
bool ConnectsKinds(EdgeKind edge, VertexKind a, VertexKind b);

// The record tags the reader accepts, from one table (g2o_tags.cc) that also
// gives the writer its tags, boxplus-g2o --list-types its list and the fuzzer
// its tags: a tag, the format it comes from, and the numbers after it.
enum class TagFamily { kG2o, kBoxplus, kToro, kGtsam };
struct TagInfo {
  std::string tag;
  TagFamily family;
  std::string fields;  // e.g. "id x y theta"
};
std::vector<TagInfo> RecordTags();
const char* ToString(TagFamily family);
// The tag FormatG2o writes a record of this kind under (toro: the record was
// read from a TORO or GTSAM line, Vertex/Edge::toro).
const char* WrittenTag(VertexKind kind, bool toro);
const char* WrittenTag(EdgeKind kind, bool toro);

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
